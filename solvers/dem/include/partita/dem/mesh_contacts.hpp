#pragma once
// Contacts of a sphere with the triangle meshes (faces, edges, vertices, each counted once), their
// tangential histories carried from feature to feature, and the reduction of the contact forces to
// the meshes' triangles and vertices. Stateless: the histories and the last pass's records are
// per-particle arrays of the System's store (slots of max_contacts per particle).

#include "partita/dem/contact_model.hpp"
#include "partita/dem/mesh_contact_record.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class MeshContacts {
 public:
  /// Contacts one particle keeps with mesh features at a time; further ones are ignored.
  static constexpr int max_contacts = 8;

  struct Particle {  ///< what the contact law reads about the sphere
    const Eigen::Vector3d& x;
    double r;
    const Eigen::Vector3d& v;
    double m;
    const Eigen::Vector3d& w;
    int material;
  };
  struct History {  ///< the store's mesh-contact arrays (particle i: slots [i max_contacts, ...))
    int* count;
    std::int64_t* key;
    Eigen::Vector3d* shear;
    MeshContactRecord* records;
  };

  /// Adds the mesh contact forces and torques of particle i to f and t, updates its slots;
  /// Load: also the largest F_n (E*/R*)^2 into load (R* = R).
  template <bool Load>
  static void evaluate(int i, const Particle& q, const NeighborList& lists,
                       const std::vector<TriangleMesh>& meshes, const ContactModel& model,
                       const History& history, double dt, bool update_history, Eigen::Vector3d& f,
                       Eigen::Vector3d& t, double& load);
  /// The meshes' triangle and vertex forces from the records of n particles.
  static void reduce(int n, const int* slot_count, const MeshContactRecord* records,
                     std::vector<TriangleMesh>& meshes);
};

}  // namespace partita::dem
