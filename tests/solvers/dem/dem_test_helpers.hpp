#pragma once
// Shared set-ups for the DEM tests.

#include "partita/dem/system.hpp"

#include <cmath>
#include <numbers>

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
