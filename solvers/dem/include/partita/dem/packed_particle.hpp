#pragma once
// The moving state of a particle, what a contact kernel reads about it as a neighbour and the
// force sums it writes, packed in two cache lines (128 bytes, aligned): System keeps positions,
// velocities, angular velocities, forces and torques here while stepping and mirrors them into
// the store's arrays on demand. A listed pair whose spheres do not overlap reads the first line
// (x, r); a contact reads and writes both. Mass and material, constant while stepping, are read
// from the store's arrays (12 bytes a particle: the neighbours' entries stay in the L1 cache).

#include <Eigen/Core>

namespace partita::dem {

struct alignas(64) PackedParticle {
  Eigen::Vector3d x;  ///< position [m]
  double r;           ///< radius [m]
  Eigen::Vector3d v;  ///< velocity [m/s]
  Eigen::Vector3d w;  ///< angular velocity [rad/s]
  Eigen::Vector3d f;  ///< force sum of the current pass [N]
  Eigen::Vector3d t;  ///< torque sum of the current pass [N m]
};
static_assert(sizeof(PackedParticle) == 128, "two cache lines");

}  // namespace partita::dem
