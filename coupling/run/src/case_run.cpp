// CaseRun, the window loop: the scheme advances one window, the services observe it
// (service.hpp), until the case's end or a stop request. What the services are and do is theirs
// (src/services/); restart files are the list of their sections (restart_file.hpp).
#include "partita/run/case_run.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/run/remote_participant.hpp"
#include "restart_file.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on
namespace fs = std::filesystem;

void CaseRun::run() {
  if (options_.check_only) return;
  if (serves()) return serve();
  Stopwatch wall;
  const bool resumed = start();
  try {
    advance_windows(resumed);
  } catch (...) {
    for (const auto& s : services_) s->finish(/*failed=*/true);  // the complete rows stay
    report();
    throw;
  }
  finish(wall);
}

// The window loop: the scheme advances a window, the services observe it (the initial state of
// a new run as window 0), until the case's end or a service asks to stop.
void CaseRun::advance_windows(bool resumed) {
  auto notify = [&](FinishedWindow& w) {
    for (const auto& s : services_) s->observe(w);
  };
  if (!resumed) {
    scheme_->initialize();
    FinishedWindow initial;
    notify(initial);
  }
  for (std::int64_t n = state_->windows_done; n < window_count_; ++n) {
    const TimeWindow window(window_size_, n, 1);
    const WindowReport r = scheme_->advance(window);
    state_->finished(n + 1, r);
    FinishedWindow w;
    w.window = n + 1;
    w.time = window.end();
    w.report = &r;
    w.last = n + 1 == window_count_;
    notify(w);
    if (options_.on_window) options_.on_window(w.window, window_count_, w.time, r.iterations);
    if (w.signal != 0) return stopped_by(w);
  }
}

// A new run prepares its folder; a resumed one changes nothing in its folder before the restart
// file has been read and accepted (resume()). Returns whether the run resumes.
bool CaseRun::start() {
  const bool resumed = !options_.resume_dir.empty();
  const fs::path resume_file = resumed ? newest_restart_file(output_dir_) : fs::path();
  if (resumed)
    if (const std::string why = restart_blocker(); !why.empty())
      throw Error("cannot resume from " + resume_file.string() + ": " + why);
  if (!resumed) prepare_folder();
  build_services();
  if (resumed) resume(resume_file);
  for (const auto& s : services_) s->start(resumed);
  log::get("coupling")->info(
      "case '{}': {} windows of {:.6g} s to t = {:.6g} s, scheme {}, participants {}; output in "
      "{}{}",
      name_, window_count_, window_size_, static_cast<double>(window_count_) * window_size_,
      scheme_->name(),
      [&] {
        std::vector<std::string> n;
        for (auto& p : participants_) n.push_back(p->name());
        return join_names(n);
      }(),
      output_dir_.string(),
      resumed ? fmt::format("; resumed after window {} from {}", state_->windows_done,
                            resume_file.filename().string())
              : std::string());
  return resumed;
}

void CaseRun::stopped_by(const FinishedWindow& w) {
  summary_.stopped_by_signal = w.signal;
  report();
  log::get("coupling")->warn(
      "stopped by signal {} after window {} (t = {:.6g} s){}", w.signal, w.window, w.time,
      summary_.last_restart.empty()
          ? std::string()
          : "; continue with: partita run CASE --resume " + output_dir_.string());
}

// The end of a run (also one stopped by a signal): the services close their files, the
// participants finalize, and the wall time is split into its parts.
void CaseRun::finish(const Stopwatch& wall) {
  scheme_->stop_threads();  // the participants' threads (a concurrent parallel scheme)
  for (const auto& s : services_) s->finish(/*failed=*/false);
  for (auto& p : participants_) {
    Stopwatch sc;
    p->finalize();
    p->add_seconds(sc.seconds());
  }
  report();
  summary_.wall_seconds = wall.seconds();
  double accounted = summary_.output_seconds;
  for (auto& p : participants_) {
    summary_.participant_seconds.emplace_back(p->name(), p->seconds());
    accounted += p->seconds();
  }
  for (auto& e : exchanges_) summary_.mapping_seconds += e->mapping_seconds();
  accounted += summary_.mapping_seconds;
  summary_.overlap_seconds = scheme_->overlap_seconds();
  accounted -= summary_.overlap_seconds;  // counted twice above: both participants worked
  summary_.core_seconds = std::max(0.0, summary_.wall_seconds - accounted);
  log_summary();
}

// The controller runs the windows; this process answers for its participant.
void CaseRun::serve() {
  Stopwatch wall;
  ParticipantServer server(*options_.distributed.controller, options_.stop_signal);
  summary_.stopped_by_signal =
      server.serve(*served_, [this](std::size_t exchange, const InterfaceMesh& from,
                                    const InterfaceMesh& to) {
        return server_mapping(exchange, from, to);
      });
  summary_.wall_seconds = wall.seconds();
  summary_.participant_seconds.emplace_back(served_->name(), served_->seconds());
  log::get("coupling")->info(
      "participant '{}' served the run: {:.3f} s in its solver, {:.3f} s mapping what it read, "
      "of {:.3f} s",
      served_->name(), served_->seconds(), server.mapping_seconds(), summary_.wall_seconds);
}

void CaseRun::prepare_folder() {
  Stopwatch clock;  // the output folder and an earlier run's VTK files: output time
  fs::create_directories(output_dir_ / "vtk");
  if (const int removed = remove_pvd_series(output_dir_ / "vtk"); removed > 0)
    log::get("coupling")->info("removed {} VTK files of an earlier run from {}", removed,
                               (output_dir_ / "vtk").string());
  output_seconds_ += clock.seconds();
}

void CaseRun::resume(const fs::path& file) {
  RestartParts parts;
  parts.run = state_.get();
  for (const auto& s : services_) parts.services.push_back(s.get());
  parts.scheme = scheme_.get();
  for (const auto& p : participants_) parts.participants.push_back(p.get());
  read_restart_file(file, parts);
  const std::int64_t done = state_->windows_done;
  if (done >= window_count_)
    throw Error(fmt::format(
        "{}: the restart point is window {} (t = {:.6g} s), and the case ends there (window "
        "{}): nothing to continue; raise time.end, e.g. --set time.end={:.6g}",
        file.string(), done, static_cast<double>(done) * window_size_, window_count_,
        2.0 * static_cast<double>(done) * window_size_));
  // Accepted: now the services' state and their files.
  for (const auto& s : services_) s->restored();
  summary_.resumed_from = done;
}

void CaseRun::report() {
  summary_.windows = state_->windows_done;
  summary_.iterations = static_cast<long>(state_->iterations);
  summary_.unconverged_windows = static_cast<long>(state_->unconverged_windows);
  summary_.max_window_iterations = state_->max_window_iterations;
  summary_.output_seconds = output_seconds_;
  for (const auto& s : services_) s->report(summary_);
}

void CaseRun::log_summary() const {
  auto logger = log::get("coupling");
  for (const auto& p : participants_)
    if (const std::string t = p->transport_summary(); !t.empty())
      logger->info("participant '{}' in another process: {}", p->name(), t);
  std::string parts;
  for (const auto& [n, s] : summary_.participant_seconds)
    parts += fmt::format("{} {:.3f} s, ", n, s);
  if (const std::vector<int> omp = scheme_->concurrent_omp_threads(); !omp.empty()) {
    std::string each;
    for (const int t : omp) each += fmt::format("{}{}", each.empty() ? "" : ", ", t);
    parts += fmt::format("(at the same time on threads, OpenMP threads {}: overlap -{:.3f} s), ",
                         each, summary_.overlap_seconds);
  }
  logger->info(
      "summary: {} windows, {} iterations (mean {:.2f}, max {}{}); wall {:.3f} s = {}mapping "
      "{:.3f} s, output {:.3f} s, core {:.3f} s{}{}",
      summary_.windows, summary_.iterations, summary_.mean_iterations(),
      summary_.max_window_iterations,
      summary_.unconverged_windows
          ? fmt::format(", {} windows at max_iterations", summary_.unconverged_windows)
          : std::string(),
      summary_.wall_seconds, parts, summary_.mapping_seconds, summary_.output_seconds,
      summary_.core_seconds,
      summary_.energy_warnings
          ? fmt::format("; {} windows with the coupling creating energy beyond the tolerance",
                        summary_.energy_warnings)
          : std::string(),
      summary_.imbalance_warnings
          ? fmt::format("; {} windows with an exchange off balance", summary_.imbalance_warnings)
          : std::string());
  for (const auto& s : services_) s->log_summary();
}

}  // namespace partita::run
