#pragma once
// Adapter of the native DEM solver (solvers/dem) to the Solver contract.
//
// YAML (see spec() or `partita docs dem`): materials, interactions, particles (generated to a
// porosity or read from a LAMMPS data file), walls (planes, boxes), meshes (STL files or
// generated rectangles) that are coupling interfaces, gravity, time step fraction, skin.
//
// For each mesh {name: M} it exposes two coupling meshes:
//   M          the mesh vertices with their triangles (reference configuration):
//              reads "displacement" [m] (vertices placed at reference + displacement; the wall
//              velocity follows from the motion), writes "force" [N] (contact forces distributed
//              to the vertices by barycentric weights: the conservative route)
//   M_centres  the triangle centroids: writes "force" [N] per triangle and "traction" [Pa] =
//              force / triangle area (the seed's route, Algorithm 1 of seed 000); a triangle's
//              force is lumped from its vertices' (continuous as contacts cross triangle edges:
//              see dem::TriangleMesh::triangle_forces)
//              It reads "attached" [-]: a triangle whose value is below 1/2 leaves the contacts
//              (an eroded FE element's face: FemAdapter's N_centres writes it).
// interface_work(M): the work the motion of M did on the particles (energy audit); none on
// M_centres (what it reads moves nothing).
// Monitors: kinetic_energy [J], momentum_x|y|z [kg m/s] (sum m v: with the meshes' and walls'
// forces and gravity, the impulse balance of a bed that is not at rest), the energy accounting
// (dem::System::energies(), cumulative since the first step) friction_work, damping_work,
// breakage_energy, stiffening_work, gravity_work, wall_work (all walls and meshes), M.work and
// <wall>.work [J], elastic_energy [J] and energy_balance_error [-] (each a pass over the particles:
// computed when asked for), M.force_x|y|z [N] (force of the particles on mesh M),
// particle.<id>.x|y|z [m] and .vx|vy|vz [m/s] for the ids in monitor_particles,
// <wall>.force_x|y|z [N] (a box wall: all its faces), <wall>.<face>.force_x|y|z [N] (each closed
// face of a box wall, faces xmin..zmax), particles, contacts_per_particle; with `breakage`:
// breakage.events, .fragments, .fragment_mass [kg], .mass_lost [kg], .mass_restored [kg],
// .energy_released [J], .powder_events, .powder_mass [kg], .powder_energy [J],
// stable_time_step [s] (it falls as fragments appear; `auto` substeps follow
// it), and the grading (cumulative mass passing per size) appended to
// <output>/<participant>_grading.csv at each output time. With output: {particles_file: end |
// every-output} the particles are written as a LAMMPS data file that particles: {file: ...} reads
// back bit for bit: <output>/<participant>.data at finalize() (and
// <output>/particles/<participant>_<frame>.data at each output time).
//
// On several ranks (SolverContext::ranks: mpirun -n N partita run CASE for a DEM-only case, or
// -n N before --participant in a run of participants as processes): the bed split over the ranks,
// one subdomain each, rank 0 leading the others (dem_ranks.cpp, which says what is handled and
// what is refused). The coupled data are the same bits on any N.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "partita/dem/breakage.hpp"
#include "partita/dem/packing_generator.hpp"
#include "partita/dem/system.hpp"
#include "partita/dem/wall_servo.hpp"
#include "partita/interface/interface_work.hpp"
#include "partita/interface/monitor_table.hpp"
#include "partita/interface/solver.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

class DemAdapter : public Solver {
 public:
  explicit DemAdapter(const SolverContext& context);
  ~DemAdapter() override;

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override;
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override;
  double stable_time_step() const override;
  void advance(double dt) override;
  double time() const override { return system_.time(); }
  void save_checkpoint() override;
  void restore_checkpoint() override;
  void write_output(const OutputFrame& frame) override;
  std::vector<std::pair<std::string, std::string>> output_files() const override { return files_; }
  std::string check_state() const override;
  std::vector<MeshRequest> mesh_requests() const override { return requests_; }
  void receive_mesh(const std::string& name, const Mesh& mesh) override;
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override;
  void read_restart(BinaryReader& in) override;
  std::vector<MonitorValue> monitors() const override;
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override;
  std::optional<double> interface_work(std::string_view mesh) const override;
  void finalize() override;

  /// The participant's keys (dem_schema.cpp); the adapter is built from them (dem_build.cpp).
  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Solver> create(const SolverContext& context);
  /// The monitor quantities: their docs (registration) and values (dem_monitors.cpp).
  static const MonitorTable<DemAdapter>& monitor_table();
  /// The faces of a box wall, bit k of Wall::faces: kFaces[k].
  static constexpr std::array<std::string_view, 6> kFaces = {"xmin", "xmax", "ymin",
                                                             "ymax", "zmin", "zmax"};

 private:
  struct CouplingMesh {
    std::string name;
    int id = -1;                 // DEM mesh id
    Eigen::MatrixX3d reference;  // vertex positions, reference configuration
    Eigen::VectorXd areas;       // triangle areas (reference) [m^2]
    Eigen::MatrixX3d positions;  // current vertex positions (work array)
    // The interface energy audit (Solver::interface_work): the work the moving mesh did on the
    // particles since t = 0, with f_v the contact forces on the vertices (barycentric: exact for
    // the linear motion of each triangle).
    InterfaceWork audit = InterfaceWork::motion({}, {});  // started by add_coupling_mesh
  };
  struct Wall {
    std::string name;
    int id = -1;
    unsigned faces = 0;   // a box wall: its closed faces (bit k: kFaces[k]); 0: a plane wall
    bool moving = false;  // velocity from a table
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // times table(t)
    TimeTable table;
    // on several ranks, a servo's law applied by the adapter with the force summed over the
    // ranks (dem_ranks.cpp); in one process the System's dem::WallServo hook
    std::optional<dem::WallServoParameters> servo;
  };
  /// One entry of `materials` (dem_schema.cpp).
  static std::shared_ptr<const config::Spec> material_spec();
  /// Index into meshes_dem_ of the coupling mesh `mesh` (vertices or centres); throws if unknown.
  std::size_t find(std::string_view mesh, bool* centres) const;
  void add_breakage(const config::Node& breakage);
  const dem::Breakage* breakage() const;  ///< nullptr when off
  void write_grading(const OutputFrame& frame, const dem::Particles& particles) const;
  /// The particles as a LAMMPS data file (dem::LammpsData), written atomically.
  void write_particles_file(const std::filesystem::path& file) const;
  void write_particles_file(const dem::Particles& particles,
                            const std::filesystem::path& file) const;

  std::string name_;
  std::filesystem::path output_dir_;
  std::string particles_file_ = "none";  // output.particles_file: none, end, every-output
  dem::System system_;
  double time_step_fraction_ = 0.2;
  bool time_step_fraction_auto_ = false;  // not given: from the restitutions in use
  dem::SystemState checkpoint_;
  bool has_checkpoint_ = false;
  std::vector<CouplingMesh> meshes_dem_;
  std::vector<Wall> walls_;
  std::vector<InterfaceMesh> meshes_;
  std::vector<std::pair<std::string, std::string>> files_;
  // the domain's bounding box (particles at the start, box walls, plane points, meshes) and the
  // margin
  Eigen::Vector3d domain_lo_ = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d domain_hi_ = Eigen::Vector3d::Constant(-1e300);
  double lost_margin_ = 0.0;
  // stable_time_step() cached for the particle count it was computed for
  static constexpr std::size_t kNoCount = static_cast<std::size_t>(-1);
  mutable double stable_ = 0.0;
  mutable std::size_t stable_for_count_ = kNoCount;
  mutable double stable_fraction_ = -1.0;
  bool lost_margin_given_ = false;
  /// lost_margin when the case gives none: the domain's largest edge, and never below
  /// kLostDiameters largest particle diameters (one sphere on a plane has a box of one height).
  double default_lost_margin() const;
  /// check_state()'s message for the first particle that is not finite or lies beyond the
  /// domain and lost_margin (empty: none); restored: worded for a state read from a file.
  std::string particle_astray(bool restored) const;
  static constexpr double kLostDiameters = 5.0;
  /// At set-up, a particle farther than kAbsurdFactor times the size of the box walls' and
  /// meshes' domain outside it is refused (a unit slip: mm read as m is 1000).
  static constexpr double kAbsurdFactor = 100.0;
  // meshes taken from other participants (meshes: [{from: participant.mesh}]), with materials
  std::vector<MeshRequest> requests_;
  std::vector<int> request_materials_;
  std::vector<char> request_one_sided_;
  void add_coupling_mesh(const std::string& name, const Mesh& mesh, int material, bool one_sided);
  /// read() of "attached" on M_centres: a triangle whose value is below 1/2 leaves the contacts.
  void set_attached(const CouplingMesh& cm, const Eigen::MatrixXd& values);
  int breakage_ = -1;  // hook index of the breakage model, -1: off
  // monitor_particles: the ids whose position and velocity are monitor quantities
  // particle.<id>.x|y|z|vx|vy|vz, the index where each was last found (ids are stable, indices
  // change when the particles are renumbered) and its last state (kept once breakage removed it)
  std::vector<std::int64_t> tracked_;
  mutable std::vector<std::size_t> tracked_index_;
  mutable std::vector<std::array<double, 6>> tracked_last_;

  // ---- on several ranks (dem_ranks.cpp): the bed split over the participant's ranks ----
  struct OnRanks;                   // dem_ranks.hpp
  std::unique_ptr<OnRanks> ranks_;  // null: one process (system_ holds the whole bed)
  bool on_ranks() const { return ranks_ != nullptr; }
  /// At the end of the constructor with SolverContext::ranks: refuses what a split does not
  /// handle yet (naming the key), sets up the transport, cuts the bed (ranks_split()) unless it
  /// waits for meshes from other participants, claims the ranks.
  void setup_ranks(const SolverContext& context);
  /// Cuts the bed into the ranks' boxes and sets up the stepper, on every rank alike, once every
  /// mesh is in (at set-up, or after the last mesh taken from another participant).
  void ranks_split();
  /// (rank 0) The command `bytes` to every other rank; (the others) the next command.
  void tell_others(const std::vector<std::byte>& bytes) const;
  std::vector<std::byte> next_command() const;
  /// (rank 0) What the Solver contract asks, told to the others and done together.
  void lead_advance(double dt);
  std::vector<MonitorValue> lead_monitors(const std::vector<std::string>& names) const;
  std::string lead_check() const;
  void lead_output(const OutputFrame& frame);
  std::string lead_restart() const;
  /// (finalize() with output.particles_file) The particles file written from every rank's.
  void lead_particles_file(const std::filesystem::path& file);
  /// The restart stream resumed on every rank; the check of the state (empty: fine).
  std::string lead_resume(const std::string& stream, const std::string& source);
  /// (restore_checkpoint()) The split bed of save_checkpoint() resumed on every rank.
  void lead_restore(const std::string& stream);
  /// (the leader) A mesh taken from another participant, passed on to the others.
  void lead_mesh(const std::string& name, const Mesh& mesh) const;
  /// Coupled data of meshes_dem_[k]: read (the leader passes the values on ahead of its next
  /// command; what: displacement 1, attached 2) and written (forces summed over the ranks; what:
  /// vertex forces 3, triangle forces 4, tractions 5).
  void lead_read(std::size_t k, std::uint32_t what, const Eigen::MatrixXd& values);
  void ranks_read(std::size_t k, std::uint32_t what, const Eigen::MatrixXd& values);
  void lead_write(std::size_t k, std::uint32_t what, Eigen::MatrixXd& values) const;
  void ranks_write(std::size_t k, std::uint32_t what, Eigen::MatrixXd& values) const;
  /// What every rank does for a command (collective); each starts the stepper first if no
  /// command has (its first force pass, on every rank at the same command).
  void ranks_start() const;
  void ranks_advance(double dt);
  void ranks_rebalance();
  void ranks_set_changed() const;
  void ranks_monitors(std::uint32_t groups) const;
  std::string ranks_check() const;
  void ranks_output(const OutputFrame& frame);
  std::string ranks_restart() const;
  void ranks_resume(const std::string& stream);
  /// Every owned particle to rank 0, in the order of their ids (there; empty elsewhere).
  dem::Particles ranks_particles() const;
  void ranks_particles_file(const std::filesystem::path& file) const;
  /// (ranks other than 0) Follows rank 0's commands until it ends the run: the exit status.
  int follow();
  /// (rank 0) Tells the others that the run has ended with `status` (after a failure here).
  void end_others(int status);
  /// (rank 0) The monitor groups that `names` need; throws Error for a quantity not on ranks.
  std::uint32_t ranks_monitor_groups(const std::vector<std::string>& names) const;
  std::vector<std::string> ranks_monitor_names() const;
  /// check_state()'s message for particle i (not finite or astray).
  std::string astray_message(std::size_t i, bool restored) const;
};

}  // namespace partita::adapters
