#pragma once
// `partita run CASE` for a case with a `sweep` section: every variant in its own process (this
// executable with --no-sweep and the variant's --set values), at most `jobs` at once, the
// progress of the whole sweep on stderr, then DIR/sweep.csv and DIR/sweep.png (not with
// --no-plots, which the variants get too).

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "partita/coupling/registries.hpp"
#include "partita/interface/error.hpp"

namespace partita::app {

struct SweepOptions {
  std::filesystem::path case_file;
  std::filesystem::path output_dir;    ///< empty: out/<case name>/
  std::vector<std::string> overrides;  ///< the user's --set values (every variant gets them)
  /// Where each override comes from, for the check's messages (empty: "command line (--set ...)";
  /// a front end in another program names its own call).
  std::vector<SourceLocation> override_origins;
  int jobs = 1;
  int threads = 1;  ///< threads of the whole sweep (shared by the jobs)
  std::string log_level = "info";
  bool plots = true;  ///< the variants' PNG plots and sweep.png (false: --no-plots)
  std::vector<std::string> plugins;  ///< the --plugin libraries (every variant gets them)
  const std::atomic<int>* stop_signal = nullptr;
  /// The `partita` executable that runs each variant (empty: this process's own executable,
  /// /proc/self/exe; a front end in another program names it).
  std::filesystem::path executable;
};

/// Whether the case file (with the overrides) declares a sweep.
bool has_sweep(const std::filesystem::path& case_file, const std::vector<std::string>& overrides);

/// Run the sweep; returns the exit status (0: every variant ran; 1: some failed; 128 + N: a
/// signal stopped it).
int run_sweep(const coupling::Registries& registries, const SweepOptions& options);

}  // namespace partita::app
