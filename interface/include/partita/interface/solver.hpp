#pragma once
// The Solver contract: what an adapter implements so that the coupling core can drive a solver
// without knowing what it computes.
//
// Call order (the coupling core guarantees it):
//
//   1. The factory builds the solver from its YAML section (SolverContext); the solver reads
//      its own inputs and sets up its initial state (time 0).
//   2. mesh_requests() — once after every participant is built; receive_mesh() once per
//      request with the other participant's mesh. Then meshes() — called once; the list and the
//      reference coordinates of its meshes stay fixed for the whole run.
//   3. Once before the first window: write_output(frame 0) and monitors() for t = 0, and the
//      core asks write() for the initial values of every exchanged field.
//   4. For every time window [t_n, t_n + Δt]:
//        (implicit schemes) save_checkpoint()            — state at t_n
//        for every substep k of the window:
//          read(mesh, data, values)  for each field it receives (values already mapped to its
//                                    mesh and interpolated in time to the substep's end)
//          advance(dt_k)             — one step of its own physics, dt_k <= stable_time_step()
//          write(mesh, data, values) for each field it sends (the core combines substeps)
//        (implicit schemes, not converged) restore_checkpoint() and repeat the window
//      after an accepted window: monitors(); write_output() when an output time is reached;
//      write_restart() when a restart point is due (or, in a resumed run, read_restart() once
//      instead of the initial write() of step 3).
//   5. finalize() — once, after the last window (close files, print summaries).
//
// read() may be called several times before one advance(); the last call for a field wins.
// A field's values are N x C matrices: N = the mesh's number of points, C = its components.
// partita::check_solver_contract (conformance.hpp) checks an implementation against this
// contract; docs/writing_an_adapter.md walks through one, in tree and out of tree.

#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/mesh.hpp"
#include "partita/interface/participant_ranks.hpp"
#include "partita/interface/vtk_xml.hpp"

namespace partita {

/// How a field behaves under mapping between non-matching meshes.
enum class DataKind {
  intensive,  ///< a density or a point value (displacement, traction): mapped consistently
  extensive,  ///< an amount that adds up (force): mapped conservatively, sums preserved
};

/// A field a solver sends or receives on one of its meshes.
struct DataSpec {
  std::string name;    ///< "displacement", "traction", "force", "pressure", ...
  int components = 3;  ///< columns of the values matrix
  std::string unit;    ///< SI unit, e.g. "m", "Pa", "N"
  DataKind kind = DataKind::intensive;
};

/// A mesh a solver exposes to the coupling, with what it can receive and send on it.
struct InterfaceMesh {
  Mesh mesh;
  std::vector<DataSpec> reads;   ///< fields the solver accepts through read()
  std::vector<DataSpec> writes;  ///< fields the solver provides through write()
  /// Its motion is prescribed (a driven rigid body's surface): it takes no load back, and the
  /// work done through it on a participant that reads its motion is that participant's input
  /// (the case lists it in energy.inputs), not energy passed between the two: the coupling's
  /// energy audit of the pair leaves such exchanges out.
  bool prescribed = false;
};

/// A surface a solver takes from another participant at set-up (e.g. an FE face as a DEM wall):
/// the core hands over that participant's interface mesh (points with triangles, reference
/// configuration) through Solver::receive_mesh().
struct MeshRequest {
  std::string name;    ///< the name the receiving solver gives it
  std::string source;  ///< "participant.mesh" as the case wrote it
  config::Node where;  ///< the YAML key, for messages
};

/// A scalar the solver reports after each accepted window (for monitors / CSV).
struct MonitorValue {
  std::string name;  ///< e.g. "kinetic_energy", "plate.force_z"
  std::string unit;  ///< SI unit, e.g. "J", "N"
  double value = 0.0;
};

/// Where and when write_output() writes.
struct OutputFrame {
  std::filesystem::path vtk_directory;  ///< DIR/vtk of the run (exists)
  std::string prefix;                   ///< participant name: files start with it
  int index = 0;                        ///< frame number, 0, 1, 2, ...
  double time = 0.0;                    ///< simulated time [s]
  vtk::Options vtk;                     ///< format of the VTK files (case key output.vtk)
};

/// The abstract solver a coupling participant wraps. See the call order above.
class Solver {
 public:
  virtual ~Solver() = default;

  /// The coupling meshes in the reference configuration, with their readable/writable fields.
  virtual const std::vector<InterfaceMesh>& meshes() const = 0;

  /// Surfaces this solver takes from other participants (default: none).
  virtual std::vector<MeshRequest> mesh_requests() const { return {}; }
  /// One requested surface, handed over by the core before meshes() is used.
  virtual void receive_mesh(const std::string& name, const Mesh& mesh) {
    throw Error("this solver takes no meshes from other participants (asked for '" + name + "')");
  }

  /// Give the solver the values of a field it receives (N x C on that mesh's points).
  virtual void read(std::string_view mesh, std::string_view data,
                    const Eigen::MatrixXd& values) = 0;

  /// Ask the solver for the values of a field it sends (resized to N x C by the solver, every
  /// value set: the array the core passes may hold the numbers of an earlier call, or none).
  virtual void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) = 0;

  /// The largest step the solver can take now [s]; +infinity when unconditionally stable.
  virtual double stable_time_step() const { return std::numeric_limits<double>::infinity(); }

  /// One step of the solver's own physics, of length dt [s].
  virtual void advance(double dt) = 0;

  /// The solver's current time [s].
  virtual double time() const = 0;

  /// Keep the complete state (one slot); restore_checkpoint() returns to it bit for bit.
  virtual void save_checkpoint() = 0;
  virtual void restore_checkpoint() = 0;

  /// Restart files (`partita run CASE --resume DIR`). Called between windows only, after the
  /// solver was built from the same case: write_restart() writes everything that evolves (what
  /// save_checkpoint() keeps, plus anything read() set that the next window does not set again);
  /// read_restart() in a new process returns the solver to that state, so that the run goes on
  /// bit for bit as if it had never stopped. A solver that cannot returns false from
  /// supports_restart() (the defaults below); runs with it then write no restart files.
  virtual bool supports_restart() const { return false; }
  virtual void write_restart(BinaryWriter& out) const {
    throw Error("this solver does not support restart files");
  }
  virtual void read_restart(BinaryReader& in) {
    throw Error("this solver does not support restart files");
  }

  /// Write VTK files for this frame under frame.vtk_directory (the core keeps one .pvd series
  /// per series name from what output_files() returns after this call).
  virtual void write_output(const OutputFrame& frame) {}

  /// Files written by the last write_output() call, relative to vtk_directory, with a series
  /// name each (e.g. {"particles", "granules_particles_000012.vtp"}).
  virtual std::vector<std::pair<std::string, std::string>> output_files() const { return {}; }

  /// Scalar quantities after the last accepted window (all of them: names, units, values).
  virtual std::vector<MonitorValue> monitors() const { return {}; }

  /// Only the named quantities (unknown names are left out). The core calls this once per
  /// window with the quantities the case records. The default filters monitors(); a solver with
  /// expensive quantities (energies over a whole mesh) overrides it to compute only those asked.
  virtual std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const {
    std::vector<MonitorValue> all = monitors(), out;
    for (auto& v : all)
      for (const auto& n : names)
        if (v.name == n) out.push_back(v);
    return out;
  }

  /// A cheap check of the state after each accepted window: a diagnosis (what is wrong, where,
  /// what to change) when it is no longer physical (non-finite values, particles lost from the
  /// domain, displacements larger than the model), else "". The core stops the run with it.
  virtual std::string check_state() const { return {}; }

  /// The interface energy audit: the work [J] done on this solver, from t = 0 to the end of its
  /// last step, by what it reads on `mesh` (received loads: their work on its own displacements;
  /// a received motion: the work the moving boundary does on the solver's bodies), integrated
  /// with the trapezoidal rule over its own steps, restored with checkpoints and restart files.
  /// nullopt where the solver does not track it (the default). The core pairs the meshes two
  /// participants read from each other: a lossless interface does no net work, so the sum over
  /// both sides is the energy the coupling itself creates (the README's "Energy audit").
  virtual std::optional<double> interface_work(std::string_view mesh) const {
    return std::nullopt;
  }

  /// Once after the last window.
  virtual void finalize() {}
};

/// What a solver factory receives.
struct SolverContext {
  std::string name;                  ///< participant name in the case
  config::Node config;               ///< the participant's YAML section
  std::filesystem::path case_dir;    ///< folder of the case file (relative inputs)
  std::filesystem::path output_dir;  ///< the run's output folder
  int threads = 1;                   ///< threads the solver may use
  /// The processes this participant runs on (mpirun -n N partita run CASE for a case of one
  /// participant; participant_ranks.hpp); null: this process alone. A solver that does not run
  /// on several ranks ignores it (the run is then refused on more than one).
  std::shared_ptr<ParticipantRanks> ranks = nullptr;
};

using SolverFactory = std::function<std::unique_ptr<Solver>(const SolverContext&)>;

}  // namespace partita
