#include "restart_files.hpp"

#include <fmt/format.h>

#include "partita/interface/log.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;
namespace fs = std::filesystem;

void RestartFiles::observe(FinishedWindow& w) {
  if (w.initial()) return;
  const bool due =
      (settings_.every_windows > 0 && w.window % settings_.every_windows == 0) ||
      (settings_.every_seconds > 0.0 && since_restart_.seconds() >= settings_.every_seconds) ||
      (w.last && settings_.at_end) || w.signal != 0;
  if (!due) return;
  if (blocker_.empty()) {
    write(w.window);
    since_restart_.restart();
  } else if (w.signal != 0) {
    log::get("coupling")->warn("no restart file: {}", blocker_);
  }
}

void RestartFiles::write(std::int64_t windows_done) {
  Stopwatch clock;
  fs::create_directories(dir_);
  const fs::path path = dir_ / fmt::format("w{:012d}.bin", windows_done);
  write_restart_file(path, parts_);
  last_ = path;
  // keep the newest `keep` files
  auto files = restart_files(dir_);
  for (std::size_t i = 0; i + static_cast<std::size_t>(settings_.keep) < files.size(); ++i) {
    std::error_code ec;
    fs::remove(files[i].second, ec);
  }
  seconds_ += clock.seconds();
  log::get("coupling")->debug("restart file {} ({:.3f} s)", path.string(), clock.seconds());
}

void RestartFiles::report(RunSummary& summary) const {
  summary.output_seconds += seconds_;
  if (!last_.empty()) summary.last_restart = last_;
}

}  // namespace partita::run
