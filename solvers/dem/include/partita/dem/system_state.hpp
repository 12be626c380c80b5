#pragma once
// A full in-memory copy of a System's dynamic state (particles, walls, mesh vertices, neighbour
// lists with contact histories, forces, time). Restoring it and stepping on gives results
// bit-identical to never having left (implicit coupling repeats windows from such states).

#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/particles.hpp"
#include "partita/dem/plane_wall.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

/// Result of one particle-mesh contact in the last force evaluation.
struct MeshContactRecord {
  int mesh = 0;
  int triangle = 0;
  std::array<double, 3> barycentric{};
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< on the particle [N]
  double delta = 0.0;                               ///< overlap [m]
  double r_eff = 0.0;
  int material = 0;
};

class SystemState {
 public:
  double time() const { return time_; }
  long step_count() const { return steps_; }

 private:
  friend class System;
  Particles particles_;
  std::vector<PlaneWall> planes_;
  std::vector<TriangleMesh> meshes_;
  NeighborList neighbors_;
  std::vector<Eigen::Vector3d> plane_shear_;
  std::vector<std::int64_t> mesh_slot_key_;
  std::vector<Eigen::Vector3d> mesh_slot_shear_;
  std::vector<int> mesh_slot_count_;
  std::vector<MeshContactRecord> mesh_records_;
  std::vector<Eigen::Vector3d> wall_force_;
  double time_ = 0.0;
  long steps_ = 0;
  bool forces_valid_ = false;
  bool prepared_ = false;
  int builds_since_sort_ = 0;
};

}  // namespace partita::dem
