#pragma once
// Spheres as contiguous arrays, one per quantity (structure of arrays). SI units.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

struct Particles {
  std::vector<Eigen::Vector3d> position;          ///< centre [m]
  std::vector<Eigen::Vector3d> velocity;          ///< [m/s]
  std::vector<Eigen::Vector3d> angular_velocity;  ///< [rad/s]
  std::vector<Eigen::Vector3d> force;             ///< total force of the last step [N]
  std::vector<Eigen::Vector3d> torque;            ///< total torque about the centre [N m]
  std::vector<double> radius;                     ///< [m]
  std::vector<double> mass;                       ///< [kg]
  std::vector<double> inertia;                    ///< moment of inertia 2/5 m R^2 [kg m^2]
  std::vector<int> material;                      ///< material id
  std::vector<std::int64_t> id;                   ///< caller's id (default: index)

  std::size_t size() const { return radius.size(); }
  void reserve(std::size_t n) {
    position.reserve(n), velocity.reserve(n), angular_velocity.reserve(n), force.reserve(n);
    torque.reserve(n), radius.reserve(n), mass.reserve(n), inertia.reserve(n);
    material.reserve(n), id.reserve(n);
  }
};

}  // namespace partita::dem
