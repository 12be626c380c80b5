#pragma once
// Fills an axis-aligned box with spheres of a discrete size distribution to a target porosity,
// deterministically from a seed.
//
// Method: the number of spheres of each size follows from the box volume, the porosity and the
// number (or mass) fractions; the spheres are placed uniformly at random inside the box (shuffled
// sizes, own 64-bit generator, so the result depends on the seed only), then overlaps are removed
// by Jacobi relaxation: every overlapping pair is pushed apart along its normal (each sphere by a
// share inversely proportional to its volume) and spheres are kept inside the box, until the
// largest overlap is below max_overlap * R_min. Porosities above random loose packing (~0.4) are
// reachable; 0.5 takes a few hundred sweeps. The spheres come out in cell order (by z, then y,
// then x, cells 2 R_max wide), so that neighbours have nearby indices (the solver's cache and
// thread parts depend on it).

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

struct PackingSpec {
  enum class Basis { number, mass };
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();  ///< box corner [m]
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();  ///< opposite corner [m]
  std::vector<double> diameters;                 ///< [m]
  std::vector<double> fractions;                 ///< one per diameter, any positive scale
  Basis basis = Basis::number;                   ///< fractions by number or by mass (volume)
  double porosity = 0.5;                         ///< 1 - solid volume / box volume
  std::uint64_t seed = 1;
  double max_overlap = 0.01;  ///< largest allowed overlap as a fraction of the smallest radius
  int max_sweeps = 20000;
  /// Called after every relaxation sweep with the sweep number and the largest overlap as a
  /// fraction of the smallest radius (progress of long generations); may be empty.
  std::function<void(int sweep, double overlap)> progress;
};

struct Packing {
  Eigen::MatrixX3d positions;  ///< N x 3 centres, in cell order
  Eigen::VectorXd radii;       ///< N
  double porosity = 0.0;       ///< realised, 1 - sum V / box volume
  double max_overlap = 0.0;    ///< realised largest overlap [m]
  int sweeps = 0;              ///< relaxation sweeps used
};

class PackingGenerator {
 public:
  /// Throws Error on inconsistent input (sizes, fractions, porosity out of (0.3, 1), box too
  /// small) or when the overlap bound is not reached within max_sweeps.
  static Packing generate(const PackingSpec& spec);
};

}  // namespace partita::dem
