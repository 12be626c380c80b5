#pragma once
// Result of one particle-mesh contact in the last force evaluation (kept per particle and contact
// slot, for the deterministic mesh-force reduction, the history hand-over and the energies).

#include <array>

#include <Eigen/Core>

namespace partita::dem {

struct MeshContactRecord {
  int mesh = 0;
  int triangle = 0;
  std::array<double, 3> barycentric{};
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< on the particle [N]
  double delta = 0.0;                               ///< overlap [m]
  double r_eff = 0.0;
  int material = 0;
  /// The overlap the contact had when its triangle entered the contacts (a face that erosion
  /// exposed under the particle) [m], followed down as the particle moves out; the force acts on
  /// the overlap beyond it (`delta` is that part). 0 for a contact made by approach. (Single
  /// precision: the 4 bytes after `material`, which the records need anyway: they go into state
  /// files as raw bytes, and padding would carry whatever the heap held there.)
  float pre_overlap = 0.0f;
};
static_assert(sizeof(MeshContactRecord) == 3 * sizeof(int) + sizeof(float) + 8 * sizeof(double),
              "no padding: the records are written as raw bytes");

}  // namespace partita::dem
