#pragma once
// The moving state of a particle and what a contact kernel reads about it, packed in 96 bytes
// (two cache lines instead of one per array): System keeps positions, velocities and angular
// velocities here while stepping and mirrors them into the store's arrays on demand.

#include <Eigen/Core>

namespace partita::dem {

struct PackedParticle {
  Eigen::Vector3d x;  ///< position [m]
  double r;           ///< radius [m]
  Eigen::Vector3d v;  ///< velocity [m/s]
  double m;           ///< mass [kg]
  Eigen::Vector3d w;  ///< angular velocity [rad/s]
  int material;
};

}  // namespace partita::dem
