#pragma once
// A DEM simulation of spheres with Hertz-Mindlin contacts against each other, rigid planes and
// movable triangle meshes.
//
// Call order:
//   1. set-up: add_material() (ids 0, 1, ...), add_interaction() for every pair of materials
//      that can touch (particle-particle and particle-wall/mesh), optionally
//      set_damping_model(), set_gravity(), set_skin();
//      add_particle()/add_particles(), add_plane()/add_box(), add_mesh() -> ids.
//   2. dt = time_step_fraction * rayleigh_time_step() (a dt above the Rayleigh step throws).
//   3. loop: [set_vertex_positions(mesh, X[, V]) / set_wall_velocity()] then step(dt) or
//      run(n, dt); read monitors (kinetic_energy(), wall_force(), mesh_force(),
//      triangle_forces(), vertex_forces()) and write output (write_particles_vtp(), ...).
//   4. implicit coupling: save_state() at the window start, restore_state() to repeat it.
// The first step checks that every material pair in use has an interaction and builds the
// neighbour lists; adding particles, walls or meshes later is allowed (lists are rebuilt and the
// contact histories of new contacts start at zero).
//
// Integration: velocity Verlet (v += dt/2 F/m; x += dt v; forces; v += dt/2 F/m, same for the
// angular velocity with I = 2/5 m R^2). Forces of a step do not depend on the number of
// OpenMP threads (set_num_threads()): each particle sums its contacts in a fixed order.

#include "partita/dem/contact_model.hpp"
#include "partita/dem/damping_model.hpp"
#include "partita/dem/interaction.hpp"
#include "partita/dem/material.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/particles.hpp"
#include "partita/dem/plane_wall.hpp"
#include "partita/dem/system_state.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class System {
 public:
  /// Contacts one particle keeps with mesh features (faces, edges, vertices) at a time; further
  /// ones (only in extreme geometries) are ignored.
  static constexpr int max_mesh_contacts = 8;

  System();

  // ---- set-up -------------------------------------------------------------------------------
  int add_material(const Material& material);
  void add_interaction(int material_a, int material_b, const Interaction& interaction);
  void set_damping_model(DampingModel model);
  void set_gravity(const Eigen::Vector3d& g) { gravity_ = g; }
  const Eigen::Vector3d& gravity() const { return gravity_; }
  /// Verlet skin [m] (>= 0); default 10 % of the largest radius at the first step.
  void set_skin(double skin);
  /// Renumbers the particles in cell order (by z, then y, then x) at the first step and then at
  /// every `rebuilds`-th neighbour-list build; 0 (the default) keeps the caller's numbering.
  /// Spatial order keeps neighbours close in memory and each thread's particle range compact,
  /// which matters when the input order is random or the flow mixes the particles. Indices change
  /// (the caller's ids in particles().id do not); contact histories are kept.
  void set_sort_interval(int rebuilds);
  /// Renumbers the particles in cell order now (see set_sort_interval()).
  void sort_particles();
  long sort_count() const { return sorts_; }

  /// Adds one sphere; returns its index. Throws Error on radius <= 0, unknown material or
  /// non-finite values. id < 0: the index is used.
  std::size_t add_particle(const Eigen::Vector3d& position, double radius, int material,
                           const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                           const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero(),
                           std::int64_t id = -1);
  /// Adds N spheres (positions N x 3, radii N); returns the index of the first.
  std::size_t add_particles(const Eigen::Ref<const Eigen::MatrixX3d>& positions,
                            const Eigen::Ref<const Eigen::VectorXd>& radii, int material);
  void set_particle_velocity(std::size_t i, const Eigen::Vector3d& velocity,
                             const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());

  /// An infinite plane through `point`; particles stay on the side `normal` points to.
  /// Returns the wall id.
  int add_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int material,
                const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero());
  /// An axis-aligned box [lo, hi] holding the particles inside, made of six planes with inward
  /// normals (faces: bit k of `faces` = 1 keeps face k in the order -x, +x, -y, +y, -z, +z;
  /// 0b011111 leaves the top open). Returns the wall id.
  int add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material,
              unsigned faces = 0b111111);
  /// Prescribes the translation velocity of all planes of a wall.
  void set_wall_velocity(int wall, const Eigen::Vector3d& velocity);
  int wall_count() const { return wall_count_; }

  /// A triangle mesh (vertices N x 3, triangles M x 3 vertex indices); returns the mesh id.
  int add_mesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices,
               const TriangleMesh::Triangles& triangles, int material);
  /// Moves the mesh vertices (N x 3). Without velocities, the next step takes them from the
  /// motion: V = (X - X_previous_step)/dt.
  void set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& positions);
  void set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& positions,
                            const Eigen::Ref<const Eigen::MatrixX3d>& velocities);
  void set_vertex_velocities(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& velocities);
  int mesh_count() const { return static_cast<int>(meshes_.size()); }
  const TriangleMesh& mesh(int mesh) const;

  // ---- time stepping ------------------------------------------------------------------------
  /// Rayleigh time step of the smallest particle: pi R sqrt(rho/G)/(0.1631 nu + 0.8766),
  /// minimised over particles. Throws Error when there are no particles.
  double rayleigh_time_step() const;
  /// One velocity-Verlet step. Throws Error if dt <= 0 or dt > rayleigh_time_step(), or if a
  /// material pair in use has no interaction.
  void step(double dt);
  void run(long steps, double dt);
  double time() const { return time_; }
  long step_count() const { return steps_; }

  SystemState save_state() const;
  /// Throws Error if the state comes from a system with other particles, walls or meshes.
  void restore_state(const SystemState& state);

  // ---- access and monitors ------------------------------------------------------------------
  const Particles& particles() const {
    sync_particles();
    return particles_;
  }
  std::size_t particle_count() const { return particles_.size(); }
  const ContactModel& contact_model() const { return model_; }
  const NeighborList& neighbor_list() const { return neighbors_; }
  /// Kinetic energy, translational + rotational [J].
  double kinetic_energy() const;
  /// Elastic energy stored in all contacts (Hertz 8/15 E* sqrt(R*) delta^(5/2) + tangential
  /// springs) at the current positions [J].
  double elastic_energy() const;
  /// Gravitational potential energy -sum m g.x [J].
  double potential_energy() const;
  /// Force the particles exerted on a wall (all its planes) in the last step [N].
  Eigen::Vector3d wall_force(int wall) const;
  /// Total force the particles exerted on a mesh in the last step [N].
  Eigen::Vector3d mesh_force(int mesh) const;
  /// Force on each triangle (M x 3) / each vertex (N x 3, barycentric shares) in the last step.
  const Eigen::MatrixX3d& triangle_forces(int mesh) const;
  const Eigen::MatrixX3d& vertex_forces(int mesh) const;
  /// Particle-particle pairs with overlap > 0 at the current positions.
  std::size_t contact_count() const;
  /// 2 contact_count() / N (particle-particle, as LAMMPS compute contact/atom).
  double mean_contacts_per_particle() const;

  // ---- output (VTK XML PolyData, written to a temporary name then renamed) -------------------
  void write_particles_vtp(const std::string& path) const;
  void write_mesh_vtp(int mesh, const std::string& path) const;

 private:
  void prepare();
  void check_interactions() const;
  void check_mesh(int mesh, const char* what) const;
  void resize_histories();
  // forces at the current positions; kick > 0: then v += kick F/m, omega += kick T/I
  // packed: packed_ is up to date (else it is filled first)
  // started: the sums were started (start_sums()) by the caller
  void compute_forces(double dt, bool update_history, double kick, bool started);
  void load_packed();
  void reorder_particles();
  void sync_particles() const;
  void start_sums(int i);
  void rebuild_lists();
  // Splits the particles into parts of whole blocks, one per thread; returns the count.
  int set_partition();
  int part_of(int i) const;
  // Lists the pairs whose j lies in a later part than i (after a rebuild or a new partition).
  void prepare_cross_pairs();
  struct PackedParticle;
  bool pair_force(const PackedParticle& qi, int j, int slot, double dt, bool update_history,
                  Eigen::Vector3d& force_i, Eigen::Vector3d& torque_i, Eigen::Vector3d& torque_j);
  // called inside a parallel region (orphaned omp for)
  void evaluate_forces(double dt, bool update_history, double kick);
  void reduce_wall_and_mesh_forces();
  void mesh_contacts(int i, double dt, bool update_history, Eigen::Vector3d& force,
                     Eigen::Vector3d& torque);

  ContactModel model_;
  // position, velocity and angular velocity: packed_ holds them while stepping; particles_ is
  // brought up to date on demand (mirror_valid_), and packed_ reloaded after a caller's change
  mutable Particles particles_;
  mutable bool mirror_valid_ = true;
  bool packed_valid_ = false;
  std::vector<PlaneWall> planes_;
  std::vector<TriangleMesh> meshes_;
  NeighborList neighbors_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  double skin_ = -1.0;
  int wall_count_ = 0;
  double time_ = 0.0;
  long steps_ = 0;
  bool prepared_ = false;
  bool forces_valid_ = false;
  double rayleigh_dt_ = 0.0;

  // contact histories
  std::vector<Eigen::Vector3d> plane_shear_;  // N x planes
  std::vector<std::int64_t> mesh_slot_key_;   // N x max_mesh_contacts
  std::vector<Eigen::Vector3d> mesh_slot_shear_;
  std::vector<int> mesh_slot_count_;
  // per-contact results of the last force evaluation (for deterministic wall/mesh reductions)
  std::vector<MeshContactRecord> mesh_records_;  // N x max_mesh_contacts
  struct PackedParticle {  // the moving state and what the pair loop reads about a neighbour
    Eigen::Vector3d x;
    double r;
    Eigen::Vector3d v;
    double m;
    Eigen::Vector3d w;
    int material;
  };
  std::vector<PackedParticle> packed_;
  // threads: part t owns particles [partition_[t], partition_[t+1])
  std::vector<int> partition_;
  struct CrossPair {  // a listed pair (i, j) with j in a later part than i
    int i, j, slot;
  };
  struct CrossForce {  // its force on i and torques, evaluated before the parts' row loops
    Eigen::Vector3d force_i, torque_i, torque_j;
    bool touching = false;
  };
  std::vector<CrossPair> cross_pairs_;  // by part of i, then ascending i, j
  std::vector<int> cross_out_begin_;    // parts + 1
  std::vector<int> cross_in_;           // indices into cross_pairs_, by part of j
  std::vector<int> cross_in_begin_;     // parts + 1
  std::vector<CrossForce> cross_force_;
  std::vector<int> counts_;
  bool cross_valid_ = false;
  // renumbering in cell order (scratch reused: no allocation once sized)
  int sort_interval_ = 0;
  int builds_since_sort_ = 0;
  long sorts_ = 0;
  std::vector<int> sort_key_, sort_order_, sort_new_of_old_, sort_start_;
  std::vector<Eigen::Vector3d> scratch_vec3_;
  std::vector<double> scratch_real_;
  std::vector<int> scratch_int_;
  std::vector<std::int64_t> scratch_int64_;
  std::vector<MeshContactRecord> scratch_records_;
  std::vector<Eigen::Vector3d> wall_block_force_;  // blocks x planes
  std::vector<Eigen::Vector3d> wall_force_;        // per wall
};

}  // namespace partita::dem
