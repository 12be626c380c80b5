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
  // The 4 bytes after `material`, made a member: the records go into state files as raw bytes,
  // and padding would carry whatever the heap held there (two identical runs wrote files that
  // differed in those bytes). A member is copied with the record and stays zero.
  int reserved = 0;
};
static_assert(sizeof(MeshContactRecord) == 4 * sizeof(int) + 8 * sizeof(double),
              "no padding: the records are written as raw bytes");

}  // namespace partita::dem
