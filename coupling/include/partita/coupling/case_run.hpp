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
//   output: {every: 0.1}

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "partita/coupling/coupling_scheme.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/output.hpp"

namespace partita::coupling {

struct RunOptions {
  std::filesystem::path output_dir;  ///< empty: out/<case name>/ relative to the current directory
  int threads = 1;
  bool check_only = false;  ///< validate and build everything, write nothing, run nothing
  /// "key.path[i].key=YAML value" assignments applied to the case file before validation.
  std::vector<std::string> overrides;
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
  double output_seconds = 0.0;
  double core_seconds = 0.0;  ///< the rest: scheme, acceleration, time interpolation
  double mean_iterations() const {
    return windows > 0 ? static_cast<double>(iterations) / windows : 0.0;
  }
};

class CaseRun {
 public:
  /// Parse and validate the whole case and build everything; throws partita::Error
  /// (file:line:col, key path, what is expected, did you mean).
  CaseRun(const std::filesystem::path& case_file, const Registries& registries, RunOptions options);
  ~CaseRun();
  CaseRun(const CaseRun&) = delete;
  CaseRun& operator=(const CaseRun&) = delete;

  /// Run to the end (nothing when check_only): progress line, CSV and VTK output, summary log.
  void run();

  const std::filesystem::path& output_dir() const { return output_dir_; }
  /// Post-processing scripts of the case (output.scripts), as paths; the caller runs them.
  const std::vector<std::filesystem::path>& scripts() const { return scripts_; }
  const std::string& name() const { return name_; }
  const RunSummary& summary() const { return summary_; }
  double window_size() const { return window_size_; }
  std::int64_t window_count() const { return window_count_; }
  const CouplingScheme& scheme() const { return *scheme_; }
  /// Participant by name (nullptr if none).
  Participant* participant(const std::string& name) const;

 private:
  struct Monitor;
  void build_participants(const config::Node& root);
  void build_exchanges(const config::Node& coupling);
  void build_monitors(const config::Node& root);
  void write_output(int frame, double time);

  const Registries& registries_;
  RunOptions options_;
  std::string name_;
  std::filesystem::path case_dir_, output_dir_;
  std::vector<std::filesystem::path> scripts_;
  double window_size_ = 0.0;
  std::int64_t window_count_ = 0;
  double output_every_ = 0.0;                               // 0: first and last frame only
  std::vector<std::unique_ptr<Participant>> participants_;  // in scheme order
  std::vector<std::unique_ptr<Exchange>> exchanges_;
  std::unique_ptr<CouplingScheme> scheme_;
  std::vector<Monitor> monitors_;
  std::vector<std::pair<std::string, PvdSeries>> pvds_;  // series name -> .pvd
  PvdSeries& pvd(const std::string& series);
  RunSummary summary_;
};

/// The case file's schema (for validation and `partita docs`).
std::shared_ptr<const config::Spec> case_spec(const Registries& registries);

}  // namespace partita::coupling
