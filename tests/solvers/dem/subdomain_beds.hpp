#pragma once
// The beds of the split-bed tests, without Catch (the in-process tests and the program that
// steps them on MPI ranks, tests/solvers/dem/mpi/, share them): a polydisperse packing thrown
// about, and a plate mesh that goes down and sags (as the coupling moves an FE surface).

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/packing_generator.hpp"
#include "partita/dem/system.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <vector>

#include <Eigen/Core>

namespace partita::dem::test {

/// A packing of three sizes (1, 0.8 and 0.6 mm in equal numbers, porosity 0.6) in [lo, hi], with
/// velocities of up to 0.3 m/s each way and 0.2 m/s down from a hash that starts at `hash`.
struct ThrownBed {
  Eigen::MatrixX3d x;
  Eigen::VectorXd r;
  Eigen::MatrixX3d v;
};
inline ThrownBed thrown_bed(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                            std::uint64_t seed, std::uint64_t hash) {
  PackingSpec spec;
  spec.lo = lo;
  spec.hi = hi;
  spec.diameters = {1.0e-3, 0.8e-3, 0.6e-3};
  spec.fractions = {1.0, 1.0, 1.0};
  spec.porosity = 0.6;
  spec.seed = seed;
  const Packing pk = PackingGenerator::generate(spec);
  ThrownBed out{pk.positions, pk.radii, Eigen::MatrixX3d(pk.positions.rows(), 3)};
  std::uint64_t h = hash;
  auto next = [&] {
    h ^= h >> 33, h *= 0xff51afd7ed558ccdull, h ^= h >> 33, h += 0x9e3779b97f4a7c15ull;
    return static_cast<double>(h >> 11) / 9007199254740992.0;  // [0, 1)
  };
  for (Eigen::Index i = 0; i < out.x.rows(); ++i)
    out.v.row(i) << 0.6 * next() - 0.3, 0.6 * next() - 0.3, 0.6 * next() - 0.5;
  return out;
}

/// A square plate mesh over [0, width]^2: cells^2 squares of 2 triangles, at height `start` at
/// first, going down at `speed` and sagging in the middle by up to `bulge` at time t_end.
struct SaggingPlate {
  double width = 0.0;
  int cells = 1;
  double start = 0.0, speed = 0.0, bulge = 0.0;

  Eigen::MatrixX3d vertices(double t, double t_end) const {
    Eigen::MatrixX3d x((cells + 1) * (cells + 1), 3);
    const double sag = bulge * t / t_end;
    for (int j = 0; j <= cells; ++j)
      for (int i = 0; i <= cells; ++i) {
        const double a = width * i / cells, b = width * j / cells;
        x.row(j * (cells + 1) + i) << a, b,
            start - speed * t -
                sag * std::sin(std::numbers::pi * a / width) * std::sin(std::numbers::pi * b / width);
      }
    return x;
  }
  TriangleMesh::Triangles triangles() const {
    TriangleMesh::Triangles t(2 * cells * cells, 3);
    int k = 0;
    for (int j = 0; j < cells; ++j)
      for (int i = 0; i < cells; ++i) {
        const int v = j * (cells + 1) + i;
        t.row(k++) << v, v + 1, v + cells + 2;
        t.row(k++) << v, v + cells + 2, v + cells + 1;
      }
    return t;
  }
};

/// The bed's positions (one a particle, in the order of the packing).
inline std::vector<Eigen::Vector3d> positions(const ThrownBed& b) {
  std::vector<Eigen::Vector3d> x;
  for (Eigen::Index i = 0; i < b.x.rows(); ++i) x.push_back(b.x.row(i).transpose());
  return x;
}

/// The particles (their indices) each box of `d` holds at `x`, one list a box.
inline std::vector<std::vector<int>> owned_at(const DomainDecomposition& d,
                                              const std::vector<Eigen::Vector3d>& x) {
  std::vector<std::vector<int>> keep(static_cast<std::size_t>(d.parts()));
  for (std::size_t i = 0; i < x.size(); ++i)
    keep[static_cast<std::size_t>(d.owner(x[i]))].push_back(static_cast<int>(i));
  return keep;
}

/// Adds the particles `keep` of the bed (material m, their index as id, at rest in rotation).
inline void add_bed_particles(System& sys, const ThrownBed& b, const std::vector<int>& keep,
                              int m) {
  for (const int i : keep)
    sys.add_particle(b.x.row(i).transpose(), b.r[i], m, b.v.row(i).transpose(),
                     Eigen::Vector3d::Zero(), i);
}

/// One subdomain's System as the split tests set it up alike on every subdomain: one material
/// (E = 10 MPa, nu = 0.3, 2500 kg/m^3; index 0) with friction 0.5, restitution 0.5 and rolling
/// friction 0.05 against itself, gravity -9.81 m/s^2 along z, the particles `keep` of the bed.
inline std::unique_ptr<System> bed_system(const ThrownBed& b, const std::vector<int>& keep) {
  auto sys = std::make_unique<System>();
  const int m = sys->add_material({1.0e7, 0.3, 2500.0});
  sys->add_interaction(m, m, {0.5, 0.5, 0.05});
  sys->set_gravity({0, 0, -9.81});
  add_bed_particles(*sys, b, keep, m);
  return sys;
}

}  // namespace partita::dem::test
