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
// The phases live in their own files: the schema (case_schema.cpp), building a run from a
// case (case_run_build.cpp), the run window by window (case_run.cpp), what is done after each
// window, each an observer of it (case_run_observers.cpp: the audits, the health check,
// coupling.csv, monitors and the energy balance, VTK output, signals, restart files, flushes),
// restart files and the checks (case_run_restart.cpp).
//
// Restart files: DIR/restart/w<window>.bin hold the complete state after a window (every
// participant's solver, the exchanges' values, the acceleration's history, the CSV rows and
// the VTK series so far); `partita run CASE --resume DIR` continues from the newest one bit for
// bit. Between windows the run checks every exchanged field and monitor for non-finite values
// and asks each solver for its own health check (stops with a diagnosis), and audits the
// balance of each exchange (what was sent against what arrived after mapping, coupling.csv).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "partita/coupling/coupling_scheme.hpp"
#include "partita/coupling/energy_balance.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/coupling/window_observer.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/output.hpp"

namespace partita::run {

class Channel;         // remote_participant.hpp
struct ServerMapping;  // remote_participant.hpp

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
  /// A run over several processes (remote_participant.hpp): `participant` is the one this
  /// process runs (empty: all of them, in this process). The controller (the process that runs
  /// the coupling core and writes the common files) has a channel to each other participant's
  /// process in `servers`; every other process has `controller` and only serves its participant.
  struct Distributed {
    std::string participant;
    std::vector<std::pair<std::string, Channel*>> servers;
    Channel* controller = nullptr;
  } distributed;
};

/// What run() measured.
struct RunSummary {
  std::int64_t windows = 0;
  long iterations = 0;           ///< total over the windows
  long unconverged_windows = 0;  ///< accepted at max_iterations
  int max_window_iterations = 0;
  double wall_seconds = 0.0;
  std::vector<std::pair<std::string, double>> participant_seconds;
  double mapping_seconds = 0.0;
  double output_seconds = 0.0;         ///< VTK frames, restart files, CSV rows and flushes, and the
                                       ///< removal of an earlier run's VTK files from the folder
  /// Of the participants' seconds, those that passed while another participant of this process
  /// worked too (a parallel scheme on threads, coupling.concurrent): wall = participants -
  /// overlap + mapping + output + core.
  double overlap_seconds = 0.0;
  double core_seconds = 0.0;           ///< the rest: scheme, acceleration, time interpolation
  std::int64_t resumed_from = -1;      ///< windows done by the restart file resumed (-1: none)
  int stopped_by_signal = 0;           ///< the signal that stopped the run early (0: none)
  std::filesystem::path last_restart;  ///< the newest restart file written (empty: none)
  long imbalance_warnings = 0;         ///< windows where an exchange's balance exceeded the limit
  long energy_warnings = 0;            ///< windows where the coupling created too much energy
  long energy_balance_warnings = 0;    ///< windows with |energy balance error| over its bound
  /// The largest |energy balance error| of the windows whose energy reached energy.floor (the
  /// rule of energy.tolerance: EnergyBalance::counts), and when it occurred (-1: no window
  /// counted yet).
  double max_energy_balance_error = 0.0;
  double max_energy_balance_time = -1.0;
  std::int64_t max_energy_balance_window = -1;
  long energy_balance_uncounted = 0;  ///< windows below energy.floor (not counted)
  double mean_iterations() const {
    return windows > 0 ? static_cast<double>(iterations) / windows : 0.0;
  }
};

class CaseRun {
 public:
  /// Parse and validate the whole case and build everything; throws partita::Error
  /// (file:line:col, key path, what is expected, did you mean).
  CaseRun(const std::filesystem::path& case_file, const coupling::Registries& registries, RunOptions options);
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
  const RunSummary& summary() const { return summary_; }
  double window_size() const { return window_size_; }
  std::int64_t window_count() const { return window_count_; }
  const coupling::CouplingScheme& scheme() const { return *scheme_; }
  /// Participant by name (nullptr if none).
  coupling::Participant* participant(const std::string& name) const;
  /// (check only) The external programs (solver: external): the check built the rest of the
  /// case without them; their meshes, fields and quantities are checked when they join a run.
  std::vector<std::string> external_participants() const;

 private:
  struct Monitor {
    std::string name;
    std::vector<std::pair<coupling::Participant*, std::string>> quantities;
    std::vector<std::vector<std::string>> plots;  // monitor.plots: x, then its y
    CsvSeries csv;
  };
  // What run() carries from window to window besides the solvers (restart files keep it).
  struct Progress {
    std::int64_t windows_done = 0;
    int frame = 0;
    double next_output = 0.0;
  };
  // The run's own state in a restart file (after the magic, version and byte order), one
  // serialise function for writing and reading: a reader fills a SavedRun, checks it against
  // this case and only then applies it (nothing changes before the whole file is accepted).
  struct SavedRun {
    std::string name;
    std::uint64_t identity = 0;
    double window_size = 0.0;
    Progress progress;
    std::int64_t iterations = 0, unconverged_windows = 0, imbalance_warnings = 0;
    std::int64_t energy_warnings = 0;
    int max_window_iterations = 0;
    struct Pair {
      double last_a = 0.0, last_b = 0.0, passed = 0.0;
      std::int64_t over = 0;
    };
    std::vector<Pair> pairs;  // sized from the case before reading (no count in the file)
    std::string coupling_csv;
    std::vector<std::pair<std::string, std::string>> monitors;  // name, CSV text
    std::uint8_t energy_started = 0;  // the energy balance: its initial value, its CSV text
    double energy_initial = 0.0;      // ("" without an energy section)
    std::int64_t energy_balance_warnings = 0;
    double max_energy_balance_error = 0.0;
    double max_energy_balance_time = -1.0;
    std::int64_t max_energy_balance_window = -1, energy_balance_uncounted = 0;
    std::string energy_csv;
    std::vector<std::pair<std::string, std::vector<std::pair<double, std::string>>>> pvds;
    // Written and read by the same functions (StateArchive: state_archive.hpp).
    void serialize_case(StateArchive& ar);  // name, identity, window: checked before the rest
    void serialize_state(StateArchive& ar);
  };
  SavedRun saved_run(const Progress& progress) const;
  void build_participants(const config::Node& root);
  void serve_handshake(std::unique_ptr<Solver>& solver, std::map<std::string, coupling::Substeps>& substeps,
                       bool coupled);
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
  void build_monitors(const config::Node& root);
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
  void write_output(int frame, double time);
  void write_plot_requests() const;  // DIR/<monitor>.plots, for the plot script
  void open_csv_files();   // coupling.csv, the monitors' and energy.csv (their headers)
  void flush_csv_files();

  // The observers of a finished window (window_observer.hpp), in case_run_observers.cpp;
  // window_observers() builds them in the order they act.
  class BalanceAuditObserver;
  class HealthCheckObserver;
  class CouplingCsvObserver;
  class MonitorObserver;
  class EnergyBalanceObserver;
  class EnergyAuditObserver;
  class VtkObserver;
  class StopRequestObserver;
  class RestartObserver;
  class FlushObserver;
  std::vector<std::unique_ptr<coupling::WindowObserver>> window_observers();

  // Restart files and run-time checks (case_run_restart.cpp)
  void write_restart_file(const Progress& progress);
  void read_restart_file(const std::filesystem::path& file, Progress& progress);
  std::filesystem::path newest_restart_file() const;
  /// Stops the run (throws) on non-finite exchanged values or a solver's own finding. With
  /// `after_audit`, the exchanges whose audit totals of this window were finite are not read
  /// again: a finite total has only finite terms.
  void check_window(std::int64_t window, double time, bool after_audit = false);
  /// Per audited exchange: |received total - sent total| / scale (into imbalance_).
  const std::vector<double>& audit_balance();
  std::string restart_blocker() const;  // why restart files cannot be written ("": they can)

  const coupling::Registries& registries_;
  RunOptions options_;
  std::string name_;
  std::filesystem::path case_dir_, output_dir_;
  std::vector<std::filesystem::path> scripts_;
  double window_size_ = 0.0;
  std::int64_t window_count_ = 0;
  double output_every_ = 0.0;                               // 0: first and last frame only
  vtk::Options vtk_options_;                                // output.vtk
  std::vector<std::unique_ptr<coupling::Participant>> participants_;  // in scheme order
  coupling::LocalParticipant* served_ = nullptr;  // the participant a server process runs
  config::Node served_coupling_;        // a server's: the case's coupling section (its mappers)
  std::vector<std::unique_ptr<coupling::Exchange>> exchanges_;
  std::unique_ptr<coupling::CouplingScheme> scheme_;
  std::vector<Monitor> monitors_;
  std::vector<std::pair<std::string, PvdSeries>> pvds_;  // series name -> .pvd
  PvdSeries& pvd(const std::string& series);
  RunSummary summary_;
  Progress progress_;  // what run() carries from window to window besides the solvers
  CsvSeries coupling_csv_;
  // restart files
  std::uint64_t identity_ = 0;  // hash of the case's participants and coupling sections
  std::uint64_t case_hash_ = 0;  // hash of the whole case (canonical YAML)
  // The external programs in the run (solver: external), by participant: "'program' of <peer>".
  std::map<std::string, std::string> external_programs_;
  std::int64_t restart_every_windows_ = 0;
  double restart_every_seconds_ = 0.0;
  int restart_keep_ = 2;
  bool restart_at_end_ = false;
  // the balance audit: exchanges audited and the relative imbalance that warns
  std::vector<const coupling::Exchange*> audited_;
  double balance_tolerance_ = 0.01;
  std::vector<double> imbalance_;  // audit_balance()'s result and scratch space, kept between
  Eigen::VectorXd audit_sent_, audit_received_;  // windows (no allocation per window)
  Eigen::ArrayXd audit_norm_;
  std::vector<char> audit_finite_;  // per audited exchange: this window's totals were finite
  std::vector<Eigen::VectorXd> audit_bounds_;  // per audited exchange: W^T omega (or empty)
  // the energy audit: two participants that read from each other, each with the meshes it reads
  // the other's data on (where its solver reports Solver::interface_work)
  struct EnergyPair {
    std::string label;  // "a-b"
    coupling::Participant* a = nullptr;
    coupling::Participant* b = nullptr;
    std::vector<std::string> a_meshes, b_meshes;
    // since t = 0: the work on each side at the last accepted window and the work that passed
    // (sum over windows of |change on a| + |change on b|: the scale of the audit)
    double last_a = 0.0, last_b = 0.0, passed = 0.0;
    std::int64_t over = 0;  // windows in a row above the tolerance
  };
  std::vector<EnergyPair> energy_pairs_;
  // work done on a and on b through their interface [J], and what it adds up to
  struct EnergyAudit {
    double on_a = 0.0, on_b = 0.0;
    double created() const { return on_a + on_b; }
  };
  EnergyAudit audit_energy(const EnergyPair& pair) const;
  double coupling_created() const;  // sum over the pairs of the energy created [J]
  double energy_tolerance_ = 0.5;  // created / passed that stops the run (or warns)
  bool energy_stop_ = true;
  // the energy balance of the whole system (the case's energy section; null without one), its
  // terms as (participant, quantity) in its order, DIR/energy.csv
  std::unique_ptr<coupling::EnergyBalance> energy_;
  std::vector<std::pair<coupling::Participant*, std::string>> energy_terms_;
  CsvSeries energy_csv_;
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
