#pragma once
// Shared set-ups for the DEM tests.

#include "partita/dem/packing_generator.hpp"
#include "partita/dem/system.hpp"

#include <cmath>
#include <numbers>
#include <vector>

namespace partita::dem::test {

/// One-material system with the given interaction parameters and no gravity.
inline System single_material(double youngs, double poisson, double density, double restitution,
                              double friction, DampingModel damping = DampingModel::calibrated) {
  System sys;
  const int m = sys.add_material({youngs, poisson, density});
  sys.add_interaction(m, m, {friction, restitution, 0.0});
  sys.set_damping_model(damping);
  return sys;
}

/// A random packing of spheres of the given diameters in equal numbers in the box [lo, hi].
inline Packing two_size_packing(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double d1,
                                double d2, double porosity, std::uint64_t seed) {
  PackingSpec spec;
  spec.lo = lo;
  spec.hi = hi;
  spec.diameters = {d1, d2};
  spec.fractions = {1.0, 1.0};
  spec.porosity = porosity;
  spec.seed = seed;
  return PackingGenerator::generate(spec);
}

inline double sphere_mass(double r, double rho) {
  return rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

/// Hertz impact theory (REFERENCES.md): maximum overlap, force and contact time.
struct HertzImpact {
  double delta_max, force_max, contact_time;
  HertzImpact(double m_eff, double r_eff, double e_star, double v) {
    delta_max = std::pow(15.0 * m_eff * v * v / (16.0 * e_star * std::sqrt(r_eff)), 0.4);
    force_max = 4.0 / 3.0 * e_star * std::sqrt(r_eff) * std::pow(delta_max, 1.5);
    contact_time = 2.868 * std::pow(m_eff * m_eff / (e_star * e_star * r_eff * v), 0.2);
  }
};

}  // namespace partita::dem::test
