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
//      triangle_forces(), vertex_forces()); output files are the adapter's (adapters/src/dem).
//   4. implicit coupling: save_state() at the window start, restore_state() to repeat it;
//      restart files: write_state(ostream) / read_state(istream) (versioned binary, see
//      SystemState).
// Particles live in one ParticleStore (store()): every per-particle array, the core ones and
// those of the contact histories and step hooks, is added, removed, renumbered, saved and
// restored together; particles keep a stable 64-bit id (particles().id). Models that change the
// particle set or add forces (breakage, ...) are StepHooks (add_hook()), called at fixed points
// of every step (see step_hook.hpp).
// The first step checks that every material pair that can touch has an interaction (a material
// with itself only where two particles of it exist: one sphere needs none) and builds the
// neighbour lists; adding particles, walls or meshes later is allowed (lists are rebuilt and the
// contact histories of new contacts start at zero).
//
// Integration: velocity Verlet (v += dt/2 F/m; x += dt v; forces; v += dt/2 F/m, same for the
// angular velocity with I = 2/5 m R^2; VelocityVerlet). Forces of a step do not depend on the
// number of OpenMP threads (set_num_threads()): each particle sums its contacts in a fixed order.
//
// System orchestrates; the data is owned by (see solvers/dem/README.md, "Class map"):
//   ParticleStore   every per-particle array (core arrays, wall and mesh histories, hooks' arrays)
//   VelocityVerlet  the packed moving state while stepping and its mirror into the store
//   NeighborList    cells, the pair half list (slots), plane masks, mesh candidates
//   PairContacts    per pair slot: tangential history and touching flag
//   WallContacts    planes, walls, wall forces (histories: a store array)
//   MeshContacts    the mesh contact kernel, reduction and histories (rows of the particles
//                   near a mesh only)
//   ThreadPartition parts of the particles per thread, cross pairs and their forces
//   CellOrder       renumbering in cell order
//   StepHookList    the step hooks (breakage, ...)

#include "partita/dem/cell_order.hpp"
#include "partita/dem/contact_model.hpp"
#include "partita/dem/damping_model.hpp"
#include "partita/dem/energy_sums.hpp"
#include "partita/dem/interaction.hpp"
#include "partita/dem/material.hpp"
#include "partita/dem/mesh_contact_record.hpp"
#include "partita/dem/mesh_contacts.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/packed_particle.hpp"
#include "partita/dem/pair_batch.hpp"
#include "partita/dem/pair_contacts.hpp"
#include "partita/dem/particle_store.hpp"
#include "partita/dem/particles.hpp"
#include "partita/dem/plane_wall.hpp"
#include "partita/dem/step_hook.hpp"
#include "partita/dem/step_hook_list.hpp"
#include "partita/dem/system_state.hpp"
#include "partita/dem/thread_partition.hpp"
#include "partita/dem/triangle_mesh.hpp"
#include "partita/dem/velocity_verlet.hpp"
#include "partita/dem/wall_contacts.hpp"

#include <bit>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class ExactSum;

class System {
 public:
  /// Contacts one particle keeps with mesh features (faces, edges, vertices) at a time; further
  /// ones (only in extreme geometries) are ignored.
  static constexpr int max_mesh_contacts = MeshContacts::max_contacts;

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

  /// Adds one sphere; returns its index. Between steps, the new particle starts with its weight as
  /// force (its contacts act from the next force pass) and the others keep theirs. Throws Error on
  /// radius <= 0, unknown material or non-finite values. id < 0: the next free id
  /// (ParticleStore::next_id(); the index while no id was given and nothing was removed).
  std::size_t add_particle(const Eigen::Vector3d& position, double radius, int material,
                           const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                           const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero(),
                           std::int64_t id = -1);
  /// Adds N spheres (positions N x 3, radii N); returns the index of the first.
  std::size_t add_particles(const Eigen::Ref<const Eigen::MatrixX3d>& positions,
                            const Eigen::Ref<const Eigen::VectorXd>& radii, int material);
  void set_particle_velocity(std::size_t i, const Eigen::Vector3d& velocity,
                             const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());
  /// Overrides the mass [kg] and moment of inertia [kg m^2] of particle i (default: from the
  /// material's density, 2/5 m R^2), e.g. for fragments that carry restored mass.
  void set_particle_mass(std::size_t i, double mass, double inertia);
  /// Removes the particles with remove[i] != 0 (one flag per particle); the others keep their
  /// order, ids and contact histories. The next step rebuilds the lists and recomputes forces.
  void remove_particles(const std::vector<char>& remove);
  /// Gives back the memory of the per-particle arrays beyond the particles held (after a large
  /// removal: a split bed's rank keeping its share of the bed it was built with).
  void shrink_to_fit();
  /// A particle that takes the place of part of another at run time (a fragment).
  struct Fragment {
    std::size_t parent = 0;  ///< index of the particle it replaces (removed in the same change)
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
    double radius = 0.0;
    double mass = 0.0;     ///< [kg]; <= 0: from the material's density
    double inertia = 0.0;  ///< [kg m^2] (with mass > 0)
    int material = 0;
    std::int64_t id = -1;  ///< < 0: the next free id (ParticleStore::next_id())
  };
  /// Removes the particles flagged in `remove` and appends `fragments` in their order, in one
  /// change of the set; returns the index of the first fragment. Each fragment's parent must be
  /// among the removed. By default this is remove_particles() followed by add_particle() (and
  /// set_particle_mass() where a mass is given) for each fragment: the next step searches the
  /// lists again, renumbers the particles when set_sort_interval() asks for it at a build, and
  /// computes the forces again. With set_local_fragment_insertion(true), lists built for the set
  /// before the change and every fragment's sphere inside its parent's, the lists take the
  /// fragments in without a search (NeighborList::insert_offspring(): a fragment's pairs are
  /// found among its parent's listed neighbours) and stay valid; no renumbering; each fragment
  /// starts with its parent's accelerations (the shares of the parent's last force and torque by
  /// mass and moment of inertia) until the next force pass, the other particles keep their
  /// forces. A bed that crushes then pays no neighbour search and no force pass for a change.
  std::size_t replace_particles(const std::vector<char>& remove,
                                const std::vector<Fragment>& fragments);
  void set_local_fragment_insertion(bool on) { local_fragments_ = on; }
  bool local_fragment_insertion() const { return local_fragments_; }
  /// How many changes of the set replace_particles() took in without a search.
  long local_insertions() const { return local_insertions_; }
  /// Renumbers the particles: new index k holds old particle order[k] (a permutation); ids,
  /// every per-particle array and the contact histories follow.
  void renumber_particles(const std::vector<int>& order);
  /// Particles moved to another System set up alike (another subdomain's; system_migration.cpp
  /// says what travels): pack_particles() appends to `out` one message with particles `which`
  /// (indices, each once) and everything they carry: every store array (core values, forces of
  /// the last pass, plane histories, the hooks' arrays such as breakage strengths), their mesh
  /// contacts, and the histories of their pairs keyed by particle ids. The particles stay
  /// (remove_particles() takes them out). unpack_particles() appends a message's particles in
  /// its order and returns the index of the first; their pair histories wait for the next list
  /// build and go into the slots of those pairs. It throws Error, the system unchanged, when the
  /// bytes are not such a message from a system of the same layout, or name a particle id this
  /// system holds already. (Both first size the plane histories for the planes, as a step does:
  /// a system that has not stepped yet has none.)
  void pack_particles(const std::vector<int>& which, std::vector<std::byte>& out);
  std::size_t unpack_particles(const std::byte* data, std::size_t bytes);
  /// Pair histories received and not yet placed (until the next list build; not part of a saved
  /// state: move particles between steps, not between save_state() and a step).
  std::size_t waiting_pair_histories() const { return pairs_.waiting_count(); }
  /// Every per-particle array (core and registered). Register arrays with
  /// store().add_array(); change the particle set only through add_particle() and
  /// remove_particles().
  ParticleStore& store() {
    sync_particles();
    return store_;
  }
  const ParticleStore& store() const {
    sync_particles();
    return store_;
  }
  /// The store without bringing positions, velocities and angular velocities up to date (while
  /// stepping they live in packed arrays): for a hook's per-step reading of radii, ids, materials
  /// and its own arrays at no cost.
  ParticleStore& store_unsynced() { return store_; }

  /// Adds a step hook (breakage, ...), calls its attach(); returns its index.
  int add_hook(std::unique_ptr<StepHook> hook);
  int hook_count() const { return hooks_.size(); }
  StepHook& hook(int k) { return hooks_[k]; }
  const StepHook& hook(int k) const { return hooks_[k]; }
  /// Per particle, the largest contact load F_n (E*/R*)^2 [N Pa^2/m^2] of the last force pass
  /// (F_n the normal force, E* and R* the contact's effective modulus and radius; a wall's
  /// R* = R). Recorded only while a hook wants it (StepHook::wants_contact_load()), else empty.
  const std::vector<double>& contact_load() const { return load_; }
  /// True when, in the last force pass, some particle's contact load reached its limit in the
  /// hook's limit array (StepHook::contact_load_limit()); false without such a hook.
  bool contact_load_reached() const {
    for (char c : load_reached_)
      if (c) return true;
    return false;
  }

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
  int wall_count() const { return walls_.wall_count(); }
  const std::vector<PlaneWall>& planes() const { return walls_.planes(); }

  /// A triangle mesh (vertices N x 3, triangles M x 3 vertex indices); returns the mesh id.
  int add_mesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices,
               const TriangleMesh::Triangles& triangles, int material);
  /// Moves the mesh vertices (N x 3). Without velocities, the next step takes them from the
  /// motion: V = (X - X_previous_step)/dt.
  void set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& positions);
  void set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& positions,
                            const Eigen::Ref<const Eigen::MatrixX3d>& velocities);
  void set_vertex_velocities(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& velocities);
  /// One-sided or two-sided contacts with a mesh: TriangleMesh::one_sided().
  void set_mesh_one_sided(int mesh, bool one_sided);
  /// Takes a triangle out of (or back into) the contacts: TriangleMesh::triangle_active().
  void set_triangle_active(int mesh, int triangle, bool active);
  int mesh_count() const { return static_cast<int>(meshes_.size()); }
  const TriangleMesh& mesh(int mesh) const;

  // ---- time stepping ------------------------------------------------------------------------
  /// Rayleigh time step of the smallest particle: pi R sqrt(rho/G)/(0.1631 nu + 0.8766),
  /// minimised over particles. Throws Error when there are no particles.
  double rayleigh_time_step() const;
  /// The fraction of rayleigh_time_step() at which the restitution of every interaction in use
  /// (particles with particles, planes and meshes) is realised to 1 %
  /// (RestitutionCalibration::time_step_fraction(), smallest over the interactions; 0.2 when
  /// all are elastic). Throws Error when a pair in use has no interaction.
  double time_step_fraction() const;
  /// One velocity-Verlet step. Throws Error if dt <= 0 or dt > rayleigh_time_step(), or if a
  /// material pair in use has no interaction.
  void step(double dt);
  void run(long steps, double dt);
  double time() const { return time_; }
  long step_count() const { return steps_; }

  /// A copy of the complete dynamic state: particles with ids and every registered array,
  /// contact histories (pairs, planes, meshes), neighbour lists, planes, mesh vertices, forces,
  /// time, step count and the hooks' state (counters, random-number state).
  SystemState save_state() const;
  /// Continues from a saved state: stepping on gives bit-identical results to never having left.
  /// The state may hold another number of particles (breakage, insertion) if it came from this
  /// system (or a copy of it) or was read from a stream. Throws Error if the state comes from a
  /// system with other materials, planes, meshes or hooks, or from another system with a
  /// different particle count.
  void restore_state(const SystemState& state);
  /// save_state().write(out): the versioned binary format of SystemState (restart files).
  void write_state(std::ostream& out) const;
  /// restore_state(SystemState::read(in)) for a system set up alike (materials, interactions,
  /// walls, meshes, hooks); throws Error on a bad magic, another version or a truncated stream.
  void read_state(std::istream& in);

  // ---- a step in phases (a bed split into subdomains: SubdomainStepper drives them) ---------
  /// step() cut where the subdomains of a split bed exchange data (subdomain.hpp): the same
  /// operations as step() in the same order, for one System. Each step:
  /// 1. phase_begin(dt): the walls' and meshes' motion of the step and the step's checks.
  /// 2. Either the exact path, as step() takes it where it cannot rule out a list build:
  ///    a. phase_drift(dt, skip): the integrator's first half (v += dt/2 F/m, x += dt v,
  ///       omega += dt/2 T/I) and the start of the force sums of every particle; returns the
  ///       largest squared displacement since the last list build of the particles with
  ///       skip[i] == 0 (skip: empty, or one flag per particle).
  ///    b. a ghost's values from its owner: set_phase_motion(); or, at a list build, particles
  ///       removed, added, renumbered, then phase_build().
  ///    c. phase_forces(dt, true): forces at the new positions, histories updated, the kick.
  ///    Or the fused path, as step() takes it where the last step's motion bound shows that no
  ///    build can be due (phase_fusable(), true on every subdomain):
  ///    a. phase_drift_some(dt, particles): the first half of the particles whose values go to
  ///       other subdomains before the pass;
  ///    b. the ghosts' values from their owners: set_phase_motion();
  ///    c. phase_forces_fused(dt, drifted): the force pass with the first half of every other
  ///       particle inside it, each just before the first row that reads it (its data read once
  ///       a step instead of twice), and the kick. Both paths give the same bits.
  /// 3. phase_finish(dt, moved): the meshes' positions of the step, the hooks, time and step
  ///    count (not the end_of_step() of a hook that replaces particles: the split's stepper
  ///    drives it, StepHook::replaces_particles()); moved >= 0 keeps the motion bound of the
  ///    step for the next phase_fusable() (the largest distance of a particle from its position
  ///    at the last build, over the split), moved < 0 forgets it.
  /// Before the first phase_begin() the forces of a pass must be there: phase_forces(dt, false)
  /// (no kick, no history update: what step() does before its first step). Throws Error with the
  /// energy accounting on (its sums are per System; not available in phases yet), on a bad dt
  /// (as step()), when phase_begin() finds no forces, or when a phase comes out of turn.
  void phase_begin(double dt);
  double phase_drift(double dt, const std::vector<char>& skip);
  /// Whether this step's first half moves no particle far enough for a list build (the motion
  /// bound of the last step, kept by phase_finish(dt, moved)); bound: the largest distance from
  /// the build positions after it, to keep. True for a System without particles (bound 0).
  bool phase_fusable(double dt, double& bound) const;
  void phase_drift_some(double dt, const std::vector<int>& particles);
  /// Whether a step whose largest squared particle displacement since the build is `moved2`
  /// needs new lists (a plane or mesh vertex that moved more than skin/2 also makes it).
  bool phase_needs_rebuild(double moved2) const;
  /// Position, velocity and angular velocity of particle i in the step's working state.
  void phase_motion(std::size_t i, Eigen::Vector3d& x, Eigen::Vector3d& v,
                    Eigen::Vector3d& w) const;
  void set_phase_motion(std::size_t i, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                        const Eigen::Vector3d& w);
  /// New lists for the current particles and positions (always built; no renumbering: throws
  /// Error when set_sort_interval() is not 0). passive (one flag per particle, or null): the
  /// particles whose own forces are not used (a split bed's ghosts): no pair of two of them is
  /// listed and they get no plane or mesh contacts (NeighborList::set_passive()).
  void phase_build(const std::vector<char>* passive = nullptr);
  void phase_forces(double dt, bool step);
  /// drifted: one flag per particle, 1 where the first half is not taken in the pass (taken by
  /// phase_drift_some(), or a ghost whose values came from its owner).
  void phase_forces_fused(double dt, const std::vector<char>& drifted);
  void phase_finish(double dt, double moved = -1.0);
  /// Adds to `sum` the elastic energy (as elastic_energy()) of the contacts of the last force
  /// pass that belong to the particles with skip[i] == 0 (one flag per particle): the pairs
  /// (i, j), i < j, their plane and mesh contacts. With skip = a split bed's ghosts, every
  /// contact is counted once over the subdomains (a pair where the first of its two particles in
  /// the common order is owned), each term with the bits one subdomain would give it. Throws
  /// Error without the lists of the current particles (before the first step, after a change of
  /// the particle set) or with another number of flags.
  void add_elastic_energy(const std::vector<char>& skip, ExactSum& sum) const;
  /// Records in every force pass each particle's reaction on the planes near it (off by
  /// default), for sums in an order of the caller's (a split bed's wall totals,
  /// SubdomainStepper::wall_force()); for_each_wall_reaction() reads them.
  void set_wall_reactions(bool on) {
    walls_.set_recording(on);
    prepared_ = false;  // (sizes them)
  }
  /// Whether the reactions are recorded for the current particles (set_wall_reactions(true) and
  /// a prepare since: the first step or phase_build()).
  bool wall_reactions_recorded() const {
    return walls_.recording() && walls_.reactions().size() == store_.size() * walls_.planes().size();
  }
  /// Calls visit(k, f) for each plane k near particle i at the last list build (the neighbour
  /// list's plane mask; every plane where there are more than 64): f, the force particle i
  /// exerted on plane k in the last force pass (zero without contact; the terms wall_force()
  /// sums per block). A plane not visited has no contact with i. Nothing is visited without
  /// wall_reactions_recorded() or without the lists of the current particles (zero forces).
  template <class Visit>
  void for_each_wall_reaction(std::size_t i, Visit&& visit) const {
    const std::vector<Eigen::Vector3d>& r = walls_.reactions();
    const std::size_t np = walls_.planes().size();
    if (np == 0 || !wall_reactions_recorded() || i >= store_.size()) return;
    const Eigen::Vector3d* const row = r.data() + i * np;
    if (np > 64) {
      for (std::size_t k = 0; k < np; ++k) visit(k, row[k]);
      return;
    }
    if (neighbors_.plane_mask_.size() != store_.size()) return;
    for (std::uint64_t m = neighbors_.plane_mask_[i]; m != 0; m &= m - 1)
      visit(static_cast<std::size_t>(std::countr_zero(m)), row[std::countr_zero(m)]);
  }

  // ---- access and monitors ------------------------------------------------------------------
  const Particles& particles() const {
    sync_particles();
    return store_.core();
  }
  std::size_t particle_count() const { return store_.size(); }
  const ContactModel& contact_model() const { return model_; }
  const NeighborList& neighbor_list() const { return neighbors_; }
  /// Whether the neighbour lists are those of the current particle set (every touching pair and
  /// mesh contact is among them): true after a step, false after a change of the set that the
  /// next step searches for again.
  bool lists_current() const {
    return lists_current_ && neighbors_.built() &&
           neighbors_.position_at_build_.size() == store_.size();
  }
  /// The mesh contacts: rows of the particles near a mesh at the last list build (row_count()),
  /// their contacts of the last force pass (contact_count()).
  const MeshContacts& mesh_contacts() const { return mesh_contacts_; }
  /// Kinetic energy, translational + rotational [J].
  double kinetic_energy() const;
  /// Linear momentum sum m v [kg m/s] (its rate is gravity's m g plus the walls' and meshes'
  /// forces on the particles: the impulse balance of a bed that is not at rest).
  Eigen::Vector3d linear_momentum() const;
  /// Elastic energy stored in all contacts (Hertz 8/15 E* sqrt(R*) delta^(5/2) + tangential
  /// springs) at the current positions [J]: the contacts of the last force pass with their
  /// tangential springs. Before the first step the contacts of the moment, particle pairs, planes
  /// and mesh features alike, found by a scratch neighbour search as the first pass will find
  /// them (a mesh's face, edge or vertex counted once), without tangential springs (new contacts
  /// have none); after a change of the particle set, until the next step, the pairs likewise and
  /// the mesh contacts of the last pass. The System's state is not changed.
  double elastic_energy() const;
  /// Gravitational potential energy -sum m g.x [J].
  double potential_energy() const;
  /// Cumulative energies since the first step (energy accounting; off by default: it costs
  /// ~55 % of the CPU of a step on a settled bed, bench/README.md; set_energy_tracking()).
  /// Powers are taken at the end-of-step velocities of velocity Verlet (the kick's v_{n+1}, omega_{n+1}: F_{n+1} . v_{n+1} dt summed over the steps is the
  /// trapezoidal work of the integrator, exactly), so the balance
  ///   sum(wall_work) + sum(mesh_work) + gravity
  ///     = (KE - kinetic_start) + (E_el - elastic_start) + friction + damping + breakage
  ///       + stiffening
  /// closes up to the trapezoidal rule's error on the contact springs (energy_balance_error()),
  /// where KE is taken with the integrator's half-step term: KE + sum dt/2 (F.v + T.omega) +
  /// dt^2/8 (|F|^2/m + |T|^2/I) (F, T the forces of the last pass), for which velocity Verlet's
  /// identity KE_N - KE_0 = sum_k F_k.v_k dt + B_0 - B_N holds exactly, + dt/2 sum F_c . v_wall
  /// over the wall and mesh contacts (the walls' work over half a step that sum_k F_k.v_wall dt
  /// counts beyond the trapezoidal rule). [J]
  struct Energies {
    double friction = 0.0;  ///< Coulomb sliding: power of the capped tangential forces on the
                            ///< relative motion + the spring energy the cap released
    double damping = 0.0;   ///< viscous normal and tangential contact damping, rolling resistance,
                            ///< yielding contacts (StepHook::contact_yield())
    double breakage = 0.0;  ///< stored energy (KE + E_el) before minus after changes of the
                            ///< particle set between steps (breakage, removal, insertion); no
                            ///< PE: gravity's work is booked from the motion, step by step
    double gravity = 0.0;   ///< work of gravity on the particles
    /// Mindlin's tangential springs: minus the energy they gained as their stiffness grew with
    /// the overlap at a fixed history (DissipativeParts::stiffening; mostly negative while a bed
    /// is loaded: energy the incremental law creates)
    double stiffening = 0.0;
    std::vector<double> wall_work;  ///< per wall: work of its motion on the particles
    std::vector<double> mesh_work;  ///< per mesh: work of its vertices' motion on the particles
    double kinetic_start = 0.0;     ///< kinetic energy (with the half-step term) at the first
                                    ///< step (and shifted where the step changed)
    double elastic_start = 0.0;     ///< contact elastic energy at the first step
    bool started = false;
  };
  /// Turns the energy accounting on or off (default; the force pass then skips it). Turn it on
  /// before the first step: the energies count from the first step taken with it on.
  void set_energy_tracking(bool on) { energy_tracking_ = on; }
  bool energy_tracking() const { return energy_tracking_; }
  /// What one step books for one particle (set_energy_terms()): the dissipation of its contacts
  /// (its share of each contact's dissipative power at the end-of-step velocities, its wall and
  /// mesh contacts' yield work and released spring energy, and the per-contact terms of its pairs
  /// (i, j) with j after it in the numbering), the work of gravity on it and the stiffening term
  /// [J]. Summed over the particles these are the step's increments of energies()' damping,
  /// friction, gravity and stiffening (in another order: energies() sums per block).
  struct ParticleEnergy {
    double damping = 0.0, friction = 0.0, gravity = 0.0, stiffening = 0.0;
  };
  /// Records each particle's ParticleEnergy in every step's force pass (particle_energies()),
  /// for sums in an order of the caller's (a split bed's energy accounting, SubdomainStepper::
  /// set_energy_accounting(): each subdomain adds its owned particles' terms). Unlike
  /// set_energy_tracking() it keeps no books of its own (energies() stays unstarted) and is
  /// allowed in a step taken in phases. Off by default.
  void set_energy_terms(bool on) {
    energy_terms_ = on;
    prepared_ = false;  // (sizes the sums)
  }
  bool energy_terms() const { return energy_terms_; }
  /// Per particle (current numbering), the terms of the last step's force pass; zero for a pass
  /// without a kick.
  const std::vector<ParticleEnergy>& particle_energies() const { return particle_energy_; }
  /// Adds to `sum` the half-step term of energies() (KE's dt/2 (F.v + T.omega) + dt^2/8 (|F|^2/m
  /// + |T|^2/I) and the walls' and meshes' dt/2 F_c . v_wall) of the particles with skip[i] == 0
  /// and their plane and mesh contacts (the planes' reactions need set_wall_reactions()), term by
  /// term. Throws Error without recorded reactions while planes exist, or with another number of
  /// flags.
  void add_half_step_term(const std::vector<char>& skip, double dt, ExactSum& sum) const;
  const Energies& energies() const { return energies_; }
  /// (sum(wall_work) + sum(mesh_work) + gravity - dKE - dE_el - friction - damping - breakage
  /// - stiffening)
  /// / (kinetic_start + elastic_start + |gravity| + sum |wall_work| + sum |mesh_work|); 0 before
  /// the first step. Takes a pass over the particles and contacts (kinetic and elastic energy).
  double energy_balance_error() const;
  /// The same for books `e` with the kinetic energy now (with its half-step term) and the elastic
  /// energy now (a split bed's: SubdomainStepper::energy_balance_error()).
  static double balance_error(const Energies& e, double kinetic, double elastic);

  /// Force the particles exerted on a wall (all its planes) in the last step [N].
  Eigen::Vector3d wall_force(int wall) const;
  /// The part of wall_force() on one face of a box wall (face 0..5: -x, +x, -y, +y, -z, +z, the
  /// bits of add_box()); std::nullopt for an open face. Not in the saved state: zero until the
  /// first step after restore_state() / read_state().
  std::optional<Eigen::Vector3d> wall_face_force(int wall, int face) const {
    return walls_.face_force(wall, face);
  }
  /// Total force the particles exerted on a mesh in the last step [N].
  Eigen::Vector3d mesh_force(int mesh) const;
  /// Force on each triangle (M x 3) / each vertex (N x 3, barycentric shares) in the last step.
  const Eigen::MatrixX3d& triangle_forces(int mesh) const;
  const Eigen::MatrixX3d& vertex_forces(int mesh) const;
  /// Where the steps' wall time goes, thread by thread: for measuring thread scaling
  /// (bench_dem_peers --profile). Off by default; while on, each step reads the clock about
  /// six times a thread (tens of ns each) and the physics is unchanged (the same bits).
  /// The threads' figures are those of the fused steps (one parallel region a step: no list
  /// rebuild possible; most steps of a settled bed); per thread they add up to the region's wall.
  struct StepProfile {
    struct Thread {      // seconds, summed over the fused steps
      double enter = 0;  // from the fork to this thread's start in the region
      double drift = 0;  // the integrator's first half of the particles that cross pairs read
      double drift_wait = 0;  // then waiting for the other threads (a barrier)
      double cross = 0;       // the pairs between two threads' parts
      double cross_wait = 0;  // then waiting (a barrier)
      double rows = 0;        // its part's rows (pairs, walls, meshes, the rest of the drift, kick)
      double join_wait = 0;   // from its end to the join of the region
      double busy() const { return drift + cross + rows; }
    };
    long steps = 0;               // steps taken while profiling
    long fused_steps = 0;         // of which fused
    double step_s = 0.0;          // wall of all of them [s]
    double fused_step_s = 0.0;    // wall of the fused steps [s]
    double fused_region_s = 0.0;  // of which from the fork to the join [s]
    double fused_slowest_s = 0.0;  // of which from the fork to the end of the step's slowest
                                   // thread (the rest: the join) [s]
    std::vector<Thread> threads;  // by thread number
  };
  /// Starts (and clears) or stops the step profile.
  void set_step_profiling(bool on);
  const StepProfile& step_profile() const { return profile_; }

  /// The lowest index of a particle whose position or velocity is not finite, or whose position
  /// lies more than `margin` outside the box [lo, hi] (max_k max(lo_k - x_k, x_k - hi_k) >
  /// margin); -1 when there is none. A check of a run's state, in parallel for large beds.
  std::ptrdiff_t first_particle_astray(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                       double margin) const;
  /// Particle-particle pairs with overlap > 0 at the current positions.
  std::size_t contact_count() const;
  /// 2 contact_count() / N (particle-particle, as LAMMPS compute contact/atom).
  double mean_contacts_per_particle() const;

 private:
  void prepare();
  void check_interactions() const;
  /// Particles of each material.
  std::vector<int> particles_per_material() const;
  /// Whether particles of material a can touch material b (count: particles per material, wall:
  /// materials of planes and meshes); a material touches itself only with two particles of it.
  static bool can_touch(const std::vector<int>& count, const std::vector<bool>& wall, int a,
                        int b);
  void check_mesh(int mesh, const char* what) const;
  void check_particle(std::size_t i, const char* what) const;
  void resize_histories();
  void particles_changed();
  // forces at the current positions; kick > 0: then v += kick F/m, omega += kick T/I
  // started: the sums were started (start_sums()) by the caller
  void compute_forces(double dt, bool update_history, double kick, bool started);
  void reorder_particles();
  void sync_particles() const { verlet_.sync(store_.core()); }
  // the neighbour list's slots changed (build, renumber): the pair histories follow
  void pairs_follow_lists() { pairs_.follow(neighbors_.slot_sources()); }
  void start_sums(int i);
  void rebuild_lists();
  // the integrator's motion bound after a step (VelocityVerlet::Motion): moved, the largest
  // distance from the build positions (or a bound of it), the rest from the parts' maxima
  void set_motion(double moved);
  int set_partition();
  // called inside a parallel region (orphaned omp for); drift: the pass also runs the
  // integrator's first half (step(); kick = dt/2), each particle just before a row reads it
  void evaluate_forces(double dt, bool update_history, double kick, bool drift = false);
  // Load: record the contact loads; Limit: compare them with a hook's limits; Drift: as drift
  template <bool Load, bool Limit, bool Drift, bool Energy>
  void evaluate_forces_impl(double dt, bool update_history, double kick);
  // wall totals and mesh forces of the last pass; work: with the step's kick (the pass's
  // energies into energies_)
  void reduce_wall_and_mesh_forces(double dt = 0.0, bool work = false);
  // energy accounting: the mechanical energy before a change of the particle set (taken once,
  // at the first change after a step) and its comparison after the next step's force pass
  void note_set_change();
  void settle_set_change(bool provisional = false);
  void start_load_pass(int parts);
  void write_body(BinaryWriter& out) const;
  void read_body(BinaryReader& in, std::uint32_t version);

  ContactModel model_;
  // every per-particle array; position, velocity and angular velocity: verlet_ holds them while
  // stepping; the store's copies are brought up to date on demand (sync_particles()), and the
  // packed copy reloaded after a caller's change (verlet_.invalidate())
  mutable ParticleStore store_;
  VelocityVerlet verlet_;
  WallContacts walls_;  // planes, their histories and wall forces
  std::vector<TriangleMesh> meshes_;
  NeighborList neighbors_;
  PairContacts pairs_;  // per pair slot of neighbors_: tangential histories, touching flags
  // rows of the particles near a mesh: contacts, histories, records (follow builds, renumbering)
  MeshContacts mesh_contacts_;
  StepHookList hooks_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  double skin_ = -1.0;
  double time_ = 0.0;
  long steps_ = 0;
  bool prepared_ = false;
  bool lists_current_ = false;  // the neighbour lists were built for the current particle set
  bool forces_valid_ = false;
  // phase_drift() started the force sums of the current particles (phase_forces())
  bool phase_sums_started_ = false;
  // phase_begin() was taken for this step (the first half may follow)
  bool phase_begun_ = false;
  // phase_forces_fused(): the particles whose first half is not taken in the pass (else null)
  const char* drift_skip_ = nullptr;
  bool track_load_ = false;
  double rayleigh_dt_ = 0.0;
  std::uint64_t identity_ = 0;  // shared by copies; a state remembers the system it came from
  std::vector<double> load_;    // largest contact load per particle (track_load_)
  int h_load_limit_ = -1;       // a hook's per-particle load limits (store array) or -1
  StepHook::ContactYield yield_;  // a hook's yield pressures against meshes (or none)
  std::vector<char> load_reached_;  // per part: a load reached its limit in the last pass
  struct PartMotion {  // per part, maxima after the last pass's kick: |v|^2, |F/m|^2, |x_k|
    double speed2 = 0.0, accel2 = 0.0, extent = 0.0;
  };
  std::vector<PartMotion> part_motion_;
  // energy accounting (energies()): per particle the dissipative force sums of the pass, per
  // block of particles the pass's energies, per cross pair its dissipative parts
  bool energy_tracking_ = false;
  bool energy_terms_ = false;                      // (set_energy_terms())
  std::vector<ParticleEnergy> particle_energy_;    // (the same)
  // the force pass gathers the dissipative sums (energy accounting, or its terms per particle)
  bool energy_pass() const { return energy_tracking_ || energy_terms_; }
  Energies energies_;
  std::vector<DissipationSums> dissipation_;
  std::vector<BlockEnergy> block_energy_;
  std::vector<PairEnergy> cross_energy_;
  bool set_change_pending_ = false;
  double energy_dt_ = 0.0;  // the step the energies' half-step term is taken for
  // sum_i dt/2 (F.v + T.omega) + dt^2/8 (|F|^2/m + |T|^2/I) with the forces of the last pass:
  // what velocity Verlet's kinetic energy still owes the forces' trapezoidal work, + dt/2 sum
  // F_c . v_wall over the wall and mesh contacts (Energies)
  double half_step_term(double dt) const;
  double set_change_before_ = 0.0;  // KE + E_el before the pending change
  // per part, the force pass's lists of a block of rows (pair_batch.hpp): its touching pairs,
  // their forces, where each row's pairs start and where its cross pairs start; sized by
  // start_load_pass() for the largest block (no allocation while the lists keep their size)
  struct PairScratch {
    std::vector<PairTask> tasks;
    std::vector<PairForce> forces;
    std::vector<PairEnergy> energy;  // (energy accounting)
  };
  std::vector<PairScratch> pair_scratch_;

  // step profile (set_step_profiling()): per thread, the clock (ns) at the phases of a pass
  struct alignas(64) ThreadMarks {
    std::int64_t enter = 0, drift = 0, drift_released = 0, cross = 0, cross_released = 0, rows = 0;
  };
  bool profiling_ = false;
  StepProfile profile_;
  std::vector<ThreadMarks> marks_;
  void record_fused_pass(std::int64_t fork, std::int64_t join, int parts);

  ThreadPartition partition_;
  // renumbering in cell order
  int sort_interval_ = 0;
  int builds_since_sort_ = 0;
  long sorts_ = 0;
  CellOrder cell_order_;
  std::vector<int> new_of_old_;  // scratch of remove_particles() / renumber_particles()
  bool local_fragments_ = false;
  long local_insertions_ = 0;
  std::vector<NeighborList::Offspring> offspring_;  // scratch of replace_particles()
  struct ParentShare {
    Eigen::Vector3d force, torque;
    double mass, inertia;
  };
  std::vector<ParentShare> share_;  // (the same)
  std::vector<char> set_members_;   // (the same: the particles whose energy a change alters)
  std::vector<std::size_t> set_which_;
  mutable std::vector<std::pair<int, int>> touching_;  // (set_energy(): the pairs it reads)
  double set_energy(const std::vector<std::size_t>& which, const std::vector<char>& in) const;
  // scratch of pack_particles() / unpack_particles() (kept: no allocation once grown)
  std::vector<char> chosen_;
  std::vector<std::int64_t> chosen_ids_;
  std::vector<std::int64_t> message_ids_;
};

}  // namespace partita::dem
