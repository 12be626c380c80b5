#pragma once
// The run a YAML case builds: parse and validate the whole case, build participants, mappers and
// the scheme, then run window by window, writing DIR/coupling.csv, DIR/<monitor>.csv and
// DIR/vtk/*.pvd. Schema: case_spec() (and `partita docs`); an example:
//
//   case: elastic-tube-1d
//   time: {window: 0.01, end: 1.0}              # or windows: 100
//   participants:
//     fluid: {solver: tube1d-fluid}              # plus the solver's own keys
//     solid: {solver: tube1d-solid}
//   coupling:
//     scheme: implicit-serial                    # explicit-serial|explicit-parallel|implicit-*
//     order: [fluid, solid]                      # default: file order
//     substeps: {fluid: 1, solid: auto}
//     exchanges:
//       - {data: pressure, from: fluid.nodes, to: solid.nodes, mapper: nearest-neighbor}
//       - {data: cross_section_area, from: solid.nodes, to: fluid.nodes,
//          reader_sees: linear, writer_combines: average}
//     convergence:
//       - {type: relative, data: pressure, limit: 1.0e-5}
//       - {type: relative, data: cross_section_area, limit: 1.0e-5}
//     acceleration: {type: iqn-ils, initial_relaxation: 0.01, max_columns: 50, reused_windows: 8}
//     max_iterations: 100
//     on_max_iterations: accept                  # or error
//   monitors:
//     - {name: outlet, quantities: [fluid.outlet_pressure, solid.outlet_area]}
//   energy:                                      # DIR/energy.csv (energy_balance.hpp)
//     inputs: [plate.indenter.work]
//     stored: [plate.kinetic_energy, plate.strain_energy]
//     dissipated: [plate.plastic_work]
//     tolerance: 0.02
//   output: {every: 0.1, restart: {every_windows: 100}}
//
// The phases live in their own files: the schema (case_schema.cpp); building, from the validated
// case, the participants (case_run_participants.cpp), the exchanges and the scheme
// (case_run_build.cpp) and the services' settings (case_run_services.cpp); the window loop
// (case_run.cpp). Everything a run does besides advancing its scheme is a service
// (service.hpp, src/services/): the balance audit, the divergence stop, coupling.csv, the
// monitors, the energy balance, the energy audit, VTK output, stop requests, restart files, the
// CSV flushes and the progress line, each observing the finished windows in that order.
//
// Restart files (src/restart_file.hpp): DIR/restart/w<window>.bin hold the complete state after a
// window (the loop's, each service's section, the scheme's, every participant's);
// `partita run CASE --resume DIR` continues from the newest one bit for bit.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "partita/coupling/coupling_scheme.hpp"
#include "partita/coupling/energy_balance.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/output.hpp"
#include "partita/interface/participant_ranks.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::coupling {
struct FinishedWindow;  // window_observer.hpp
class Stopwatch;        // stopwatch.hpp
}  // namespace partita::coupling

namespace partita::run {

class Channel;         // remote_participant.hpp
struct ServerMapping;  // remote_participant.hpp
class Service;         // service.hpp
struct RunState;       // (src/restart_file.hpp) the window loop's own state

struct RunOptions {
  std::filesystem::path output_dir;  ///< empty: out/<case name>/ relative to the current directory
  int threads = 1;
  bool check_only = false;  ///< validate and build everything, write nothing, run nothing
  /// "key.path[i].key=YAML value" assignments applied to the case file before validation.
  std::vector<std::string> overrides;
  /// Where each override comes from (same order; missing or empty: the command line).
  std::vector<SourceLocation> override_origins;
  /// check_only: also build the case once with each value of its sweep section set.
  bool check_sweep_values = true;
  /// Continue the run whose output folder this is from its newest restart file (the output
  /// goes to the same folder).
  std::filesystem::path resume_dir;
  /// Set (to the signal number) by a signal handler: the run finishes the current window,
  /// writes a restart file, flushes every CSV and returns (summary().stopped_by_signal).
  const std::atomic<int>* stop_signal = nullptr;
  /// Called after each finished window, once the services have observed it, on the thread that
  /// runs the run: the windows done (1-based), the run's windows, the window's end time and its
  /// iterations. For a front end's progress display (the Python module's callback); it must not
  /// throw and should return quickly.
  std::function<void(std::int64_t done, std::int64_t windows, double time, int iterations)>
      on_window;
  /// A run over several processes (remote_participant.hpp): `participant` is the one this
  /// process runs (empty: all of them, in this process). The controller (the process that runs
  /// the coupling core and writes the common files) has a channel to each other participant's
  /// process in `servers`; every other process has `controller` and only serves its participant.
  struct Distributed {
    std::string participant;
    std::vector<std::pair<std::string, Channel*>> servers;
    Channel* controller = nullptr;
  } distributed;
  /// The processes of `mpirun -n N partita run CASE` (participant_ranks.hpp): a case of one
  /// participant runs it on all of them (its solver gets them in SolverContext::ranks); a case
  /// of several is refused on more than one. With distributed.participant: that participant's
  /// processes (a solver that does not take them is refused); on its leader (rank 0) the run
  /// serves or controls as without ranks, on the others (check_only) it builds only that
  /// participant, whose solver then follows its leader's (ParticipantRanks::follow()). Null: one
  /// process.
  std::shared_ptr<ParticipantRanks> ranks = nullptr;
};

class CaseRun {
 public:
  /// Parse and validate the whole case and build everything; throws partita::Error
  /// (file:line:col, key path, what is expected, did you mean).
  CaseRun(const std::filesystem::path& case_file, const coupling::Registries& registries,
          RunOptions options);
  ~CaseRun();
  CaseRun(const CaseRun&) = delete;
  CaseRun& operator=(const CaseRun&) = delete;

  /// Run to the end (nothing when check_only): progress line, CSV and VTK output, summary log.
  void run();

  const std::filesystem::path& output_dir() const { return output_dir_; }
  /// Post-processing scripts of the case (output.scripts), as paths; the caller runs them.
  const std::vector<std::filesystem::path>& scripts() const { return scripts_; }
  const std::string& name() const { return name_; }
  /// A hash of the whole case as read (after --set), in a canonical form: comments, blank lines
  /// and key order do not change it (the processes of a distributed run compare it).
  std::uint64_t case_hash() const { return case_hash_; }
  /// This process serves one participant for a controller in another process (run() answers
  /// its requests until the run ends).
  bool serves() const { return options_.distributed.controller != nullptr; }
  /// This process runs one participant on several ranks and does not lead it: it builds only
  /// that participant, for the app to follow the leader (ParticipantRanks::follow()).
  bool follows() const {
    return options_.ranks && !options_.ranks->leads() && !options_.distributed.participant.empty();
  }
  const RunSummary& summary() const { return summary_; }
  double window_size() const { return window_size_; }
  std::int64_t window_count() const { return window_count_; }
  const coupling::CouplingScheme& scheme() const { return *scheme_; }
  /// Participant by name (nullptr if none).
  coupling::Participant* participant(const std::string& name) const;
  /// (check only) The external programs (solver: external): the check built the rest of the
  /// case without them; their meshes, fields and quantities are checked when they join a run.
  std::vector<std::string> external_participants() const;

  /// What the services are built from (case_run_services.cpp): the case's settings of each,
  /// validated, and what each observes.
  struct ServiceSettings;

 private:
  // Building (case_run_build.cpp, case_run_participants.cpp, case_run_services.cpp)
  void build_participants(const config::Node& root);
  void serve_handshake(std::unique_ptr<Solver>& solver,
                       std::map<std::string, coupling::Substeps>& substeps, bool coupled);
  bool runs_here(const std::string& participant) const {
    return options_.distributed.participant.empty() || options_.distributed.participant == participant;
  }
  void build_exchanges(const config::Node& coupling);
  // The mapper of the exchange `item` (sender field `ws`), computed from `from` to `to`; the
  // controller's for every exchange, a server's for the exchanges it maps (map_on: receiver).
  std::unique_ptr<coupling::Mapper> exchange_mapper(const config::Node& item, const DataSpec& ws,
                                                    const Mesh& from, const Mesh& to,
                                                    const std::string& label) const;
  ServerMapping server_mapping(std::size_t exchange, const InterfaceMesh& from,
                               const InterfaceMesh& to) const;
  void read_service_settings(const config::Node& root);
  void build_monitors(const config::Node& root);
  void build_energy_pairs();
  void build_energy_balance(const config::Node& root);
  // participant.quantity named by a node, checked against what the participant reports
  struct NamedQuantity {
    coupling::Participant* participant;
    std::string quantity, unit;
  };
  NamedQuantity resolve_quantity(const config::Node& q) const;
  // the participant of that name, or an error at n naming the participants
  coupling::Participant* named_participant(const config::Node& n, const std::string& name) const;
  void check_sweep_values(const std::filesystem::path& case_file, const class Sweep& sweep) const;
  std::string restart_blocker() const;  // why restart files cannot be written ("": they can)

  // The run (case_run.cpp)
  bool start();                              // folder, services, restart file; true: resumed
  void advance_windows(bool resumed);        // the window loop
  void stopped_by(const coupling::FinishedWindow& w);  // a service asked to stop after window w
  void finish(const coupling::Stopwatch& wall);  // files closed, participants finalized, summary
  void serve();                       // a server process: answer the controller until the end
  void prepare_folder();              // a new run: the output folder, an earlier run's VTK files
  void build_services();              // from settings_, in the order they observe a window
  void resume(const std::filesystem::path& file);  // a restart file read, checked and applied
  void report();                      // the services' shares into summary_
  void log_summary() const;

  const coupling::Registries& registries_;
  RunOptions options_;
  // the description a case builds
  std::string name_;
  std::filesystem::path case_dir_, output_dir_;
  std::vector<std::filesystem::path> scripts_;
  double window_size_ = 0.0;
  std::int64_t window_count_ = 0;
  std::vector<std::unique_ptr<coupling::Participant>> participants_;  // in scheme order
  coupling::LocalParticipant* served_ = nullptr;  // the participant a server process runs
  config::Node served_coupling_;  // a server's: the case's coupling section (its mappers)
  std::vector<std::unique_ptr<coupling::Exchange>> exchanges_;
  std::unique_ptr<coupling::CouplingScheme> scheme_;
  std::uint64_t identity_ = 0;   // hash of the case's participants and coupling sections
  std::uint64_t case_hash_ = 0;  // hash of the whole case (canonical YAML)
  // The external programs in the run (solver: external), by participant: "'program' of <peer>".
  std::map<std::string, std::string> external_programs_;
  std::unique_ptr<ServiceSettings> settings_;
  // the run: the loop's own state and the services
  std::unique_ptr<RunState> state_;
  std::vector<std::unique_ptr<Service>> services_;
  RunSummary summary_;
  double output_seconds_ = 0.0;  // the loop's own output time (the folder, an earlier run's files)
};

/// The case file's schema (for validation and `partita docs`).
std::shared_ptr<const config::Spec> case_spec(const coupling::Registries& registries);

/// One library of the case's `plugins:` list: its path (relative ones taken from the case file's
/// folder) and the node that names it (for messages).
struct CasePlugin {
  std::filesystem::path library;
  config::Node where;
};

/// The case's `plugins:` list (with the --set overrides applied). Read before the case is
/// validated, since the plugins add the solvers its participants name; the loading itself is
/// the executable's (app/plugin_loader.cpp).
std::vector<CasePlugin> case_plugins(const std::filesystem::path& case_file,
                                     const std::vector<std::string>& overrides);

}  // namespace partita::run
