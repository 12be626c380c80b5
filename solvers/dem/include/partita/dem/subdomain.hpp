#pragma once
// A bed split into subdomains (DomainDecomposition's boxes), each a System of its own, stepping
// to the same bits whatever the number of subdomains: positions and velocities of every particle
// id after any number of steps equal those of the bed in one subdomain stepped the same way,
// whether the subdomains are in one process (InProcessTransport) or one a rank over MPI
// (MpiSubdomainTransport, library partita::dem_mpi; tests/solvers/dem/mpi/ compare the bits).
//
// Why the bits can be the same. A particle's force is a sum in a fixed order over its local
// numbering (System::evaluate_forces(): the pairs (k, i) in ascending k, then (i, j) in
// ascending j, planes, meshes), and a pair's force and history update depend on its two
// particles' values and the order of the two alone. So an owned particle sees the same sum on any
// split when (1) every particle it can touch is there (its ghosts), with the values the owner
// has, (2) its pairs' histories are the same, and (3) the local numbering of the particles a
// subdomain holds is their order in ONE order of all particles, the same on every subdomain.
//  (1) Ghosts: at a list build, every particle within `ghost distance` = 2 R_max + skin of
//      another box (DomainDecomposition::near()) is copied to that box's subdomain with all it
//      carries (System::pack_particles()); a listed pair has its particles within
//      R_i + R_j + skin at the build, so an owned particle's every listed pair is listed where
//      it is owned. Between builds each step sends the ghosts' position, velocity and angular
//      velocity after the integrator's first half (the values the force pass reads). A ghost's
//      own force is not used (its kick is overwritten at the next refresh, the ghost replaced at
//      the next build), so the lists leave out what only it would need: no pair of two ghosts,
//      no plane or mesh contacts of a ghost (System::phase_build() with the ghosts passive); its
//      pairs with the owned particles are listed as any.
//  (2) Histories: a pair between an owned particle and a ghost is listed and evaluated on both
//      sides with the same inputs in the same order, so both keep the same history. At a build
//      every subdomain drops its ghosts and receives them again, each with the histories of its
//      pairs as its owner holds them (exact: an owner lists every pair of its particles), and a
//      particle that changes owner travels with its histories (System::pack_particles(): pair
//      records keyed by particle ids, placed at the build; plane and mesh histories in the
//      particle's arrays); a pair carried over by the receiver's own lists keeps its history
//      (both agree).
//  (3) The order: the cell of a GLOBAL grid (origin and cell size fixed for the run: the
//      decomposition's bounds and 2 R_max + skin at the start), then the particle id, applied at
//      every list build, after migration and the ghosts' exchange, by owned particles and ghosts
//      alike. Every subdomain's numbering is then a subsequence of one order, and the lists'
//      rows and every sum run in the same relative order. (The classical System orders by a
//      stable sort over its own bounding box every N builds and then by append order, which
//      depends on the set a System holds; so one subdomain stepped here differs from the same
//      bed stepped with System::step(), and the reference of a split run is this stepper with one
//      subdomain.)
//  The rebuild decision is global: the largest displacement since the build over every owned
//  particle (a max: the same in any order), so all subdomains rebuild on the same steps as one
//  subdomain would; migration (DomainDecomposition::owner() of the positions after the first
//  half) and ghosts are then settled before the lists are built.
//
// Sums over the split, and what is not handled yet:
//  - Wall forces: SubdomainStepper::wall_force() is the same on any split (each owned particle's
//    reaction on each plane near it, System::for_each_wall_reaction(), in an exact sum); it may
//    differ from System::wall_force()'s block sums in the last bits; plane_forces() gives each
//    plane's (a box wall's faces) the same way. (A ghost has no plane or mesh contacts: each System's own
//    wall_force(), mesh_force() and triangle_forces() are its owned particles', rounded in
//    another order.)
//  - Triangle meshes (STL walls, the coupling's FE surfaces): every subdomain holds every mesh
//    whole, moved alike (set_vertex_positions() on each System before the step), as the coupling
//    hands over the whole surface. A particle's contacts with the meshes are evaluated where it
//    is owned; its mesh histories travel with it at a migration (MeshContacts::pack(); a ghost
//    copy carries them too, unused). SubdomainStepper::triangle_forces(), vertex_forces() and
//    mesh_force() are the same on any split: each vertex's force an exact sum over the OWNED
//    particles' contact records, rounded once, and the triangles' shares taken from those as
//    MeshContacts::reduce() takes them. Why not each System's sums added up: a sum of
//    per-subdomain rounded sums depends on the split. They may differ from one System's triangle_forces()
//    (vertex sums rounded contact by contact) in the last bits. The messages carry only the
//    vertices the contacts touched. The energy accounting's mesh work is each owned contact's
//    (SubdomainStepper::set_energy_accounting()).
//  - An empty subdomain (no particle, not even a ghost) still moves its walls and meshes and
//    advances its time (phase_drift() and phase_finish() without particles): a moving wall or
//    mesh is where it should be when particles reach it. It asks for no list build.
//  - Ghosts: a ghost's owner is the box that holds it at the build (DomainDecomposition::owner()),
//    not the subdomain that sent the copy: a particle leaving subdomain a for b that is also a
//    ghost in c is sent to c by a, and refreshed by b until the next build.
//  - Restarts: a split bed's owned particles (Subdomain::pack_owned(): arrays, forces, pair
//    histories by id, plane and mesh histories) with one subdomain's System state for the walls,
//    meshes and time resume on any number of subdomains (SubdomainStepper::resume()), with the
//    same bits whatever the split that wrote them and the split that resumes; SplitRestart
//    writes and reads them as one stream, gathered to the process of subdomain 0 (in one
//    process, or from the ranks of an MPI split), and restores it on any number of subdomains
//    in one process or on ranks (each process reads the stream; the process of subdomain 0
//    takes every particle, resume()'s first build sends each to its owner).
//  - Energy sums: SubdomainStepper::kinetic_energy() and linear_momentum() are the same on any
//    split (exact sums over the owned particles, ExactSum, rounded once: they may differ from
//    System::kinetic_energy()'s ordered sum in the last bits), and so is elastic_energy() (each
//    pair counted where the first of its two in the global order is owned, planes and meshes
//    where the particle is owned). The energy accounting (System::energies()) is refused in
//    phases (System::phase_drift()); the split's own books are SubdomainStepper::
//    set_energy_accounting()'s: each step's terms of the owned particles in exact sums.
//  - Hooks that replace particles (breakage's fragments, powder removed: StepHook::
//    replaces_particles()): after a step each subdomain's hook chooses among the particles it
//    owns (their loads are complete there), the stepper gathers the chosen ids to every
//    subdomain and numbers the new particles from the next free id over the split in the
//    order of their parents' ids (so the ids do not depend on the split), each subdomain
//    replaces its own, then every subdomain drops its ghosts and receives them again (a list
//    build: the fragments reach the subdomains where they are ghosts, and a ghost whose owner
//    broke it goes) and a force pass without a kick gives the new set its forces, as one
//    System's step does after a change of the set. A fragment's strength and orientation are
//    drawn from (seed, id), so they too are the same on any split. The counters are exact sums
//    (hook_sums()), the breakage's energy booked over the split (set_energy_accounting()).
//    Cost: a list build and a force pass after every step in which anything broke anywhere.
//  - Wall servos and other hooks that read a wall's force read their own System's (partial, with
//    ghosts): they would steer each subdomain's wall apart; not handled.
//
// Call order: SubdomainStepper(systems, transport, decomposition, skin) with each System set up
// alike (materials, interactions, gravity, walls, meshes; the particles in any subdomain, ids
// unique over all), then start(dt) (migration, ghosts, lists, the first forces), then step(dt)
// or run(); set_decomposition() re-cuts the bed at the next list build. A restart on another
// split: each subdomain's Subdomain::pack_owned() and one subdomain's System state (the walls,
// meshes and time, alike on all); new Systems restored from that state with its particles
// removed, the messages unpacked into any of them, then resume() instead of start().
//
// The byte formats (both ends have the same byte order and types, as for state files):
//   at a build, to each subdomain d: "PSDM" (u32 magic), version (u32), the migrants' message
//     size (u64), the ghosts' message size (u64), then the two System::pack_particles()
//     messages (either absent when it holds no particle);
//   between builds, to each subdomain that holds ghosts of this one: "PGHR", version, the count
//     n (u64), then n times id (i64), x, v, omega (9 doubles), in the order of this subdomain's
//     numbering (the receiver holds them in the same relative order);
//   a collective sum, to every subdomain: the partial exact sums (ExactSum::write(), in a fixed
//     order), or for a mesh MeshForceSums::write()'s layout.

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/exact_sum.hpp"
#include "partita/dem/subdomain_transport.hpp"
#include "partita/dem/system.hpp"

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

/// The order of particles over every subdomain: by the cell of a fixed grid (cells of `cell`
/// over [lo, hi], ordered by z, then y, then x; a position outside is in the nearest cell), then
/// by id.
class GlobalOrder {
 public:
  GlobalOrder() = default;
  /// Throws Error unless lo < hi and cell > 0 (finite).
  GlobalOrder(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double cell);
  std::uint64_t cell(const Eigen::Vector3d& x) const;
  /// order[k]: the index of the k-th particle in this order; false when it is the identity.
  bool compute(const Particles& p, std::vector<int>& order);

 private:
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero();
  double cell_ = 1.0;
  Eigen::Matrix<std::int64_t, 3, 1> count_ = Eigen::Matrix<std::int64_t, 3, 1>::Ones();
  std::vector<std::pair<std::pair<std::uint64_t, std::int64_t>, int>> keys_;  // scratch
};

/// The force on one mesh's vertices as exact sums (three per vertex, only for the vertices a
/// contact touched: a coupled surface has 10^5 vertices, a subdomain's contacts touch a few) and
/// the total; as bytes for the transport. No allocation once the arrays have grown.
class MeshForceSums {
 public:
  /// Empties the sums for a mesh of `vertices` vertices.
  void reset(int vertices);
  void add_vertex(int vertex, const Eigen::Vector3d& f);
  void add_total(const Eigen::Vector3d& f);
  /// Appends the sums: the touched count (u64), the total (3 ExactSum::write_compact()), then per
  /// touched vertex its index (i64) and 3 compact ExactSum.
  void write(std::vector<std::byte>& out) const;
  /// Adds the sums of a message that write() made for a mesh with as many vertices; throws
  /// Error (naming subdomain `source`) when it does not fit.
  void add_message(const std::vector<std::byte>& in, int source);
  /// The sums rounded: the vertices' forces (untouched ones zero) and the total.
  void values(Eigen::MatrixX3d& vertex, Eigen::Vector3d& total) const;

 private:
  ExactSum* vertex_sums(int vertex);  // (makes them)
  std::vector<int> slot_;             // per vertex: the index of its sums, -1: none
  std::vector<int> vertex_;           // per index: the vertex
  std::vector<ExactSum> sums_;        // 3 per index (x, y, z)
  ExactSum total_[3];
};

/// One subdomain: its System (owned particles and ghosts) and what it sends and receives.
/// SubdomainStepper calls the phases; they are public for a driver of another shape.
class Subdomain {
 public:
  /// Registers the per-particle array "subdomain_owner" (-1: owned, else the owner's rank).
  Subdomain(System& system, int rank, int parts);
  System& system() { return *sys_; }
  const System& system() const { return *sys_; }
  int rank() const { return rank_; }
  /// Whether particle i is a ghost (since the last build).
  bool is_ghost(std::size_t i) const { return i < ghost_.size() && ghost_[i] != 0; }
  /// One flag per particle: 1 for a ghost (since the last build).
  const std::vector<char>& ghost_flags() const { return ghost_; }
  /// After a change of the set between builds (particles replaced where they are owned: new
  /// ones are owned here): the ghost flags again from the owners noted at the build.
  void set_changed();
  std::size_t owned_count() const;
  std::size_t ghost_count() const { return sys_->particle_count() - owned_count(); }
  /// Particles received as owned (migrated here) since the start.
  long migrated_in() const { return migrated_in_; }

  // ---- phases ----
  /// The walls' and meshes' motion of the step and its checks (System::phase_begin()).
  void begin(double dt);
  /// The exact path's first half (after begin()): the largest squared displacement of an owned
  /// particle since the last build, or +infinity where this subdomain's lists need a build.
  double drift(double dt);
  /// Whether the last step's motion bound rules out a build in this step (after begin();
  /// System::phase_fusable()); bound: the bound to keep after it (finish()).
  bool fusable(double dt, double& bound) const;
  /// The fused path: the first half of the owned particles that are ghosts elsewhere (their
  /// values are sent before the pass); after the ghosts' refresh, forces_fused(): the pass with
  /// every other particle's first half inside it (System::phase_forces_fused()).
  void drift_sent(double dt);
  void forces_fused(double dt);
  void pack_refresh(SubdomainMail& out);
  void unpack_refresh(const SubdomainMail& in);
  /// At a build: the particles that change owner and the ghost copies for every other subdomain
  /// (positions of now); what stays, changes role or leaves is noted for unpack_moves().
  void pack_moves(const DomainDecomposition& d, double ghost_distance, SubdomainMail& out);
  /// Removes the ghosts and the particles that left, appends what arrived, renumbers in the
  /// global order, builds the lists, notes what to send and receive until the next build.
  void unpack_moves(const SubdomainMail& in, GlobalOrder& order, const DomainDecomposition& d,
                    double ghost_distance);
  void forces(double dt, bool step);
  /// moved >= 0: the motion bound kept for fusable() (System::phase_finish()).
  void finish(double dt, double moved = -1.0);
  double max_radius();
  /// Adds the owned particles' kinetic energy (translational + rotational, System::
  /// kinetic_energy()'s terms) to sums[0] and their linear momentum m v to sums[1..3].
  void add_kinetic(ExactSum* sums);
  void add_elastic(ExactSum& sum) const { sys_->add_elastic_energy(ghost_, sum); }
  /// Adds the particle-particle contacts (listed pairs that overlap, System::contact_count()'s
  /// terms) whose first particle in the global order is owned here: each contact once over the
  /// subdomains (its pair is listed in that particle's row, where it is owned).
  void add_contacts(ExactSum& sum) const;
  /// Appends the owned particles as one System::pack_particles() message (everything they carry:
  /// arrays, forces of the last pass, pair histories by id, plane and mesh histories): with the
  /// world's state (walls, meshes, time: any subdomain's System state, they are alike) what a
  /// restart needs, whatever the split (SubdomainStepper::resume()).
  void pack_owned(std::vector<std::byte>& out);
  /// Adds the owned particles' reactions on the planes to sums[3 w + c] (wall w, component c).
  void add_wall_forces(ExactSum* sums) const;
  /// The same per plane: sums[3 k + c] (plane k of System::planes(), component c).
  void add_plane_forces(ExactSum* sums) const;
  /// Adds the owned particles' energies of the last step (System::particle_energies(): the
  /// System records them with set_energy_terms()) to sums[0..3] (damping, friction, gravity,
  /// stiffening), the work of each wall's motion on them (-their reaction . v_plane dt, as
  /// System::energies() books it per plane) to sums[4 + wall] and of each mesh's motion (the
  /// contact's force on the particle . the mesh's velocity at the contact point dt) to
  /// sums[4 + walls + mesh].
  void add_step_energies(double dt, ExactSum* sums) const;
  /// Adds the owned particles' half-step term (System::add_half_step_term()).
  void add_half_step(double dt, ExactSum& sum) const { sys_->add_half_step_term(ghost_, dt, sum); }
  /// Adds the owned particles' contacts with mesh `mesh` in the last pass to `sums` (each
  /// contact's reaction to its triangle's vertices with the contact point's barycentric weights,
  /// as MeshContacts::reduce() shares it, and to the total); the ghosts' contacts are left out.
  void add_mesh_forces(int mesh, MeshForceSums& sums) const;

 private:
  std::vector<int>& owner_array() { return sys_->store().array<int>(h_owner_); }
  // throws where the System has planes and does not record their reactions
  void check_reactions() const;

  System* sys_;
  int rank_ = 0;
  int h_owner_ = -1;
  long migrated_in_ = 0;
  std::vector<char> ghost_;               // per particle, since the last build
  std::vector<std::vector<int>> send_;    // per rank: owned particles that are ghosts there
  std::vector<std::vector<int>> recv_;    // per rank: the ghosts it owns
  std::vector<int> sent_;                 // owned particles in any send_ list, once each
  std::vector<char> drifted_;             // per particle: a ghost or in sent_ (fused pass)
  // pack_moves() -> unpack_moves()
  std::vector<char> remove_;
  std::vector<std::pair<int, int>> become_ghost_;  // (index, new owner)
  // scratch
  std::vector<std::vector<int>> migrants_, ghosts_;
  std::vector<int> near_, order_;
};

/// Steps the local subdomains of a split bed (all of them with InProcessTransport, one a rank with
// MpiSubdomainTransport).
class SubdomainStepper {
 public:
  struct Options {
    /// How far from a box a particle is a ghost there; < 0: 2 R_max + skin (what the lists
    /// need; less breaks the split's bits: a test's knob).
    double ghost_distance = -1.0;
    /// false: every step on the exact path (the fused path gives the same bits: a test's knob).
    bool fused = true;
  };
  /// systems[k]: local subdomain transport.local()[k]'s System. Sets the skin of every System
  /// (all must be alike) and the sort interval to 0. Throws Error when the counts do not match
  /// the transport's or the decomposition's.
  SubdomainStepper(std::vector<System*> systems, SubdomainTransport& transport,
                   const DomainDecomposition& decomposition, double skin, Options options);
  SubdomainStepper(std::vector<System*> systems, SubdomainTransport& transport,
                   const DomainDecomposition& decomposition, double skin)
      : SubdomainStepper(std::move(systems), transport, decomposition, skin, Options{}) {}

  /// Migration, ghosts, lists and the forces of a pass without a kick (before the first step).
  void start(double dt);
  /// Instead of start() for particles that bring the forces of their last pass (a restart: the
  /// pack_owned() messages of a split bed unpacked into any of these Systems, each set up with
  /// the world's state): migration, ghosts and lists, no force pass. The steps that follow are
  /// the same bits whatever the split that wrote the restart and whatever this one. They may
  /// differ from the run that went on without the restart in the last bits: that one builds its
  /// lists on other steps, and a build renumbers the particles (a particle's contacts summed in
  /// another order).
  void resume();
  void step(double dt);
  void run(long steps, double dt);
  /// A new decomposition (same bounds), used from the next list build on (a rebalance: the
  /// bits do not change, only where the particles are stepped).
  void set_decomposition(const DomainDecomposition& decomposition);
  const DomainDecomposition& decomposition() const { return decomposition_; }
  SubdomainTransport& transport() { return *transport_; }

  int local_count() const { return static_cast<int>(subdomains_.size()); }
  Subdomain& subdomain(int k) { return subdomains_[static_cast<std::size_t>(k)]; }
  const Subdomain& subdomain(int k) const { return subdomains_[static_cast<std::size_t>(k)]; }
  /// List builds since start() (start()'s included), the same on every subdomain.
  long builds() const { return builds_; }
  long steps() const { return steps_; }
  /// Steps taken on the fused path (the first half inside the force pass, where the motion
  /// bound of the last step rules out a build on every subdomain; the same bits as the exact
  /// path), the same on every subdomain.
  long fused_steps() const { return fused_steps_; }
  /// Kinetic energy [J] and linear momentum [kg m/s] of the owned particles of every subdomain:
  /// exact sums rounded once, the same bits on any split (collective: every process calls it).
  double kinetic_energy();
  Eigen::Vector3d linear_momentum();
  /// The contacts' elastic energy [J] (System::elastic_energy()'s terms), each contact counted
  /// once over the subdomains (System::add_elastic_energy() without the ghosts): an exact sum,
  /// the same bits on any split (collective). After a step.
  double elastic_energy();
  /// The particle-particle contacts (System::contact_count()), each counted once over the
  /// subdomains (collective). After a step.
  std::size_t contact_count();
  /// The force the particles exert on a wall (all its planes) [N] in the last pass: the owned
  /// particles' reactions in an exact sum, the same bits on any split (collective).
  Eigen::Vector3d wall_force(int wall);
  /// Every wall's wall_force() from one collective round (by wall id).
  const std::vector<Eigen::Vector3d>& wall_forces();
  /// The force the particles exert on each plane (System::planes(): a box wall's faces are its
  /// planes) [N] in the last pass, exact sums over the owned particles, the same bits on any
  /// split (collective; one round for all planes).
  const std::vector<Eigen::Vector3d>& plane_forces();
  /// The force the particles exert on mesh `mesh`'s triangles [N] in the last pass, as
  /// System::triangle_forces() defines it (each contact's reaction on its triangle's vertices
  /// with the barycentric weights, a vertex's force shared equally among its active triangles),
  /// with every vertex's force an exact sum over the owned particles' contacts, rounded once:
  /// the same bits on any split (collective). It may differ from one System's
  /// triangle_forces(), whose vertex sums are rounded contact by contact, in the last bits.
  /// Valid until the next call of triangle_forces(), vertex_forces() or mesh_force().
  const Eigen::MatrixX3d& triangle_forces(int mesh);
  /// The same sums per vertex (System::vertex_forces()); collective.
  const Eigen::MatrixX3d& vertex_forces(int mesh);
  /// The total force on mesh `mesh` [N]: the owned particles' reactions in one exact sum (the
  /// same bits on any split; System::mesh_force() adds the rounded triangle forces); collective.
  Eigen::Vector3d mesh_force(int mesh);

  /// The energy accounting over the split: the books of System::energies(), each step's terms of
  /// the owned particles (System::set_energy_terms(): their contacts' dissipation, gravity's
  /// work, the stiffening term, the walls' and meshes' work on them) added to exact sums that are
  /// never rounded until read, so that energies() and energy_balance_error() are the same bits on
  /// any split (and differ from one System's energies(), summed per block, in the last bits).
  /// Turn it on before start() or resume(). A change of the particle set by a hook (breakage's
  /// fragments) is booked as energies().breakage: the kinetic (with the half-step term) and
  /// elastic energy over the split just before the change less the same once the lists and
  /// forces are those of the new set (as System::energies() books it).
  void set_energy_accounting(bool on);
  bool energy_accounting() const { return energy_; }
  /// The books since the first step (collective): damping, friction, gravity, stiffening, each
  /// wall's and mesh's work, the kinetic energy with its half-step term and the elastic energy at
  /// the first step; unstarted (all zero) before it or without the accounting.
  System::Energies energies();
  /// As System::energy_balance_error(), from energies(), kinetic_energy(), elastic_energy() and
  /// the half-step term of the owned particles (collective). 0 before the first step.
  double energy_balance_error();
  /// The books as bytes for a restart (SplitRestart::gather()): the start values and the exact
  /// sums over every subdomain, the same on every process (collective); empty without the
  /// accounting.
  std::vector<std::byte> books();
  /// Continues the books of a restart (books()' bytes) after resume(), before the next step;
  /// throws Error when they do not fit this split's walls and meshes, or the accounting is off.
  void restore_books(const std::vector<std::byte>& bytes);

  /// Hook `hook`'s counters (StepHook::sums(), the hook of that index on every subdomain's
  /// System) added over every subdomain, each an exact sum rounded once: the same bits on any
  /// split (collective).
  std::vector<double> hook_sums(int hook);
  /// Every hook's sums over every subdomain, as exact sums (collective): what a restart keeps.
  std::vector<std::vector<ExactSum>> hook_totals();
  /// The Rayleigh time step of the smallest particle over every subdomain
  /// (System::rayleigh_time_step()), as of start(), resume() or the last change of the set.
  double rayleigh_time_step() const { return rayleigh_; }
  /// The particles over every subdomain and their mass [kg] (an exact sum): collective.
  std::pair<std::size_t, double> particle_totals();
  /// Steps after which a hook replaced particles (StepHook::replaces_particles()).
  long replacement_steps() const { return replacement_steps_; }

 private:
  // the owned contacts with `mesh` summed over every subdomain into mesh_vertex_, mesh_triangle_
  // and mesh_total_
  void mesh_sums(int mesh);
  std::vector<MeshForceSums> mesh_parts_;  // per local subdomain
  MeshForceSums mesh_all_;
  Eigen::MatrixX3d mesh_vertex_, mesh_triangle_;
  Eigen::Vector3d mesh_total_ = Eigen::Vector3d::Zero();
  std::vector<double> mesh_share_;

  void redistribute();
  // what global_sums() adds up: per local subdomain, kinetic energy and momentum (4 sums), the
  // elastic energy (1), the walls' forces (3 per wall), the planes' forces (3 per plane) or the
  // contacts (1)
  enum class Sums {
    kinetic, elastic, walls, planes, contacts, books, half_step, hook, totals
  };
  int sum_hook_ = -1;  // (global_sums(Sums::hook)'s hook)
  std::vector<Eigen::Vector3d> forces_;  // wall_forces(), plane_forces()
  // sums_[m k + q]: local subdomain k's sum q, then summed over every subdomain into totals_
  void global_sums(Sums what);
  std::vector<ExactSum> sums_, totals_;
  // the energy accounting: per local subdomain its owned particles' books (4 + walls + meshes
  // exact sums, Subdomain::add_step_energies()); the start values (as System::Energies'), the
  // step the half-step term is taken for
  bool energy_ = false;
  std::vector<std::vector<ExactSum>> books_;
  bool books_started_ = false;
  double kinetic_start_ = 0.0, elastic_start_ = 0.0, books_dt_ = 0.0;
  double sum_dt_ = 0.0;  // (global_sums(Sums::half_step)'s step)
  std::size_t book_count() const;
  std::size_t breakage_book() const { return book_count() - 1; }  // (the last)
  double half_step_term(double dt);
  // the hooks that replace particles: after a step each chooses where its particles are owned,
  // the new ones are numbered over the split (their parents' ids ascending, from the next free id
  // over every subdomain), the lists and ghosts built again and a force pass taken
  void replace_particles(double dt);
  double mechanical_energy(double dt);  // (collective: kinetic + half-step + elastic)
  void update_rayleigh();
  std::vector<int> replacing_;
  std::vector<std::vector<std::size_t>> replaced_, removed_;
  std::vector<std::vector<std::int64_t>> first_id_;
  std::vector<std::int64_t> all_ids_;
  double rayleigh_ = 0.0;
  long replacement_steps_ = 0;

  std::vector<Subdomain> subdomains_;
  SubdomainTransport* transport_;
  DomainDecomposition decomposition_, next_;
  bool next_pending_ = false;
  bool started_ = false;
  double skin_ = 0.0;
  Options options_;
  double ghost_distance_ = 0.0;
  GlobalOrder order_;
  long builds_ = 0, steps_ = 0;
  std::vector<SubdomainMail> out_, in_;
  std::vector<double> values_, bounds_;
  // every subdomain kept its motion bound at the last step's end (the fused path may be tried)
  bool motion_known_ = false;
  long fused_steps_ = 0;
  void refresh();
};

/// A split bed's restart: the world (one subdomain's System state: walls, meshes, time; alike on
/// every subdomain) and every subdomain's owned particles (Subdomain::pack_owned()), as one
/// stream. Resumed on any number of Systems set up alike (restore(), then a SubdomainStepper
/// over them and resume()), with the same bits whatever the split that wrote it, in one process
/// or over processes (each reads the stream and restores it with its transport).
/// Stream: "PSRS" (u32), version (u32), the world's size (u64) and its SystemState::write()
/// bytes, the number of parts (u64), then per part its size (u64) and its message; then the
/// energy books' size (u64) and bytes (SubdomainStepper::books(); version 2 on, 0 without the
/// accounting; version 1 is read as a restart without books); then (version 3 on) the number of
/// the System's hooks (u64) and per hook its counters' count (u64) and exact sums over the split
/// (SubdomainStepper::hook_totals(), ExactSum::write(); version 2 is read without them).
class SplitRestart {
 public:
  /// Every subdomain's owned particles, gathered through the stepper's transport to the process
  /// that steps subdomain 0, which holds the restart (holds()); on the others it is empty.
  /// Collective (every process calls it), after a step.
  static SplitRestart gather(SubdomainStepper& stepper);
  /// Whether this holds a restart (gathered here, or read).
  bool holds() const { return !world_.empty(); }
  /// Throws Error when it holds none (gathered on another process).
  void write(std::ostream& out) const;
  /// Throws Error on another magic or version, or a stream that ends early.
  static SplitRestart read(std::istream& in);
  /// Gives each of `systems` (set up alike, without particles) the world's state, and the first
  /// of them every particle (SubdomainStepper::resume() spreads them). Throws Error when a
  /// System holds particles or does not fit the world's set-up.
  void restore(const std::vector<System*>& systems) const;
  /// The same for the local subdomains of `transport` (systems[k]: local()[k]'s System) of a
  /// split over processes: every process restores the world; the particles go to the System of
  /// subdomain 0, on its process only (resume() sends each to its owner).
  void restore(const std::vector<System*>& systems, const SubdomainTransport& transport) const;
  std::size_t parts() const { return owned_.size(); }
  /// The stepper's energy books at the restart (SubdomainStepper::books(); empty without the
  /// energy accounting): SubdomainStepper::restore_books() continues them.
  const std::vector<std::byte>& books() const { return books_; }

 private:
  void restore(const std::vector<System*>& systems, int particles_to) const;
  std::vector<std::byte> books_;
  std::vector<std::vector<ExactSum>> hooks_;  // per hook of the System: its sums (or none)
  std::string world_;
  std::vector<std::vector<std::byte>> owned_;
};

}  // namespace partita::dem
