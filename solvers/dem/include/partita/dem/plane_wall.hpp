#pragma once
// A rigid infinite plane; particles live on the side its unit normal points to.
// Several planes share a wall id (a box is one wall made of up to six planes).

#include <Eigen/Core>

namespace partita::dem {

struct PlaneWall {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     ///< a point of the plane [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit normal into the particle side
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< prescribed translation [m/s]
  int material = 0;
  int wall = 0;  ///< wall id this plane belongs to
};

}  // namespace partita::dem
