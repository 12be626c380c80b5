#pragma once
// Restart files (restart_file.hpp) as a service: one every output.restart.every_windows windows,
// every every_minutes minutes, after the last window (at_end) and when a stop signal came; the
// newest output.restart.keep of them kept. A run whose participants cannot all write restart
// data writes none (on a signal it says why).

#include <cstdint>
#include <filesystem>

#include "../restart_file.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class RestartFiles final : public Service {
 public:
  struct Settings {
    std::int64_t every_windows = 0;
    double every_seconds = 0.0;
    int keep = 2;
    bool at_end = false;
  };
  /// `blocker`: why none can be written ("": they can).
  RestartFiles(const std::filesystem::path& output_dir, Settings settings, std::string blocker)
      : dir_(output_dir / "restart"), settings_(settings), blocker_(std::move(blocker)) {}
  /// What a file holds (the loop's state, the services, this one among them, the scheme, the
  /// participants), once the run has built them all.
  void set_parts(RestartParts parts) { parts_ = std::move(parts); }

  void observe(coupling::FinishedWindow& w) override;
  void report(RunSummary& summary) const override;

 private:
  void write(std::int64_t windows_done);

  std::filesystem::path dir_;
  Settings settings_;
  RestartParts parts_;
  const std::string blocker_;
  coupling::Stopwatch since_restart_;
  std::filesystem::path last_;  // the newest file written
  double seconds_ = 0.0;        // output time
};

}  // namespace partita::run
