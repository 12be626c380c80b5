#include "partita/run/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/explicit_scheme.hpp"
#include "partita/run/progress_line.hpp"
#include "partita/run/remote_participant.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/run/sweep.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace fs = std::filesystem;

PvdSeries& CaseRun::pvd(const std::string& series) {
  for (auto& [n, s] : pvds_)
    if (n == series) return s;
  pvds_.emplace_back(series, PvdSeries(output_dir_ / "vtk" / (series + ".pvd")));
  return pvds_.back().second;
}

void CaseRun::write_output(int frame, double time) {
  Stopwatch clock;
  const fs::path vtk = output_dir_ / "vtk";
  for (auto& p : participants_) {
    OutputFrame f{vtk, p->name(), frame, time, vtk_options_};
    p->write_output(f);  // counted as output time, not the participant's
    for (const auto& [series, file] : p->output_files()) {
      if (fs::path(file).has_parent_path() || file.empty() || file.front() == '.')
        throw Error("participant '" + p->name() + "' wrote the output file '" + file +
                    "', which is not a plain file name inside " + vtk.string());
      pvd(p->name() + "_" + series).add(time, file);
    }
    // interface meshes with their exchanged data
    for (const auto& im : p->meshes()) {
      VtkArrays arrays;
      for (const auto& e : exchanges_) {
        if (&e->from() == p.get() && e->from_mesh() == im.mesh.name() &&
            e->sent().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->sent());
        if (&e->to() == p.get() && e->to_mesh() == im.mesh.name() &&
            e->received().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->received());
      }
      if (arrays.empty() || im.mesh.size() > 200000) continue;
      const std::string file =
          fmt::format("{}_interface_{}_{:06d}.vtp", p->name(), im.mesh.name(), frame);
      write_vtp(vtk / file, im.mesh, arrays, {}, nullptr, vtk_options_);
      pvd(p->name() + "_interface_" + im.mesh.name()).add(time, file);
    }
  }
  summary_.output_seconds += clock.seconds();
}

void CaseRun::open_csv_files() {
  std::vector<std::pair<std::string, std::string>> columns = {{"time", "s"}, {"iterations", ""}};
  for (const auto& c : scheme_->residual_columns()) columns.push_back(c);
  for (const Exchange* e : audited_) columns.emplace_back("imbalance " + e->label(), "");
  for (const auto& p : energy_pairs_) {
    columns.emplace_back("work on " + p.a->name() + " by " + p.b->name(), "J");
    columns.emplace_back("work on " + p.b->name() + " by " + p.a->name(), "J");
    columns.emplace_back("energy created " + p.label, "J");
  }
  coupling_csv_ = CsvSeries(output_dir_ / "coupling.csv", "window", "", columns);
  for (auto& m : monitors_) {
    std::vector<std::pair<std::string, std::string>> mc;
    for (const auto& [p, q] : m.quantities) {
      std::string unit;  // only that quantity: monitors() would compute every one (energies)
      for (const auto& v : p->monitor_values({q}))
        if (v.name == q) unit = v.unit;
      mc.emplace_back(p->name() + "." + q, unit);
    }
    m.csv = CsvSeries(output_dir_ / (m.name + ".csv"), "time", "s", mc);
  }
  if (energy_) energy_csv_ = CsvSeries(output_dir_ / "energy.csv", "time", "s", energy_->columns());
}

// The monitors' plots against another quantity (monitors[].plots), one line each: x, then its
// y, as the CSV's column names without their units. plot_monitors.py reads DIR/<name>.plots
// beside DIR/<name>.csv; a monitor without plots has no such file.
void CaseRun::write_plot_requests() const {
  for (const auto& m : monitors_) {
    const fs::path file = output_dir_ / (m.name + ".plots");
    if (m.plots.empty()) {
      std::error_code ec;
      fs::remove(file, ec);  // an earlier run's
      continue;
    }
    std::ofstream out(file);
    for (const auto& xy : m.plots) out << join_names(xy, ",") << "\n";
    if (!out) throw Error("cannot write " + file.string());
  }
}

void CaseRun::flush_csv_files() {
  Stopwatch clock;
  coupling_csv_.flush();
  for (auto& m : monitors_) m.csv.flush();
  if (energy_) energy_csv_.flush();
  summary_.output_seconds += clock.seconds();
}

void CaseRun::run() {
  if (options_.check_only) return;
  auto logger = log::get("coupling");
  if (serves()) {  // the controller runs the windows; this process answers for its participant
    Stopwatch wall;
    ParticipantServer server(*options_.distributed.controller, options_.stop_signal);
    summary_.stopped_by_signal =
        server.serve(*served_, [this](std::size_t exchange, const InterfaceMesh& from,
                                      const InterfaceMesh& to) {
          return server_mapping(exchange, from, to);
        });
    summary_.wall_seconds = wall.seconds();
    summary_.participant_seconds.emplace_back(served_->name(), served_->seconds());
    logger->info(
        "participant '{}' served the run: {:.3f} s in its solver, {:.3f} s mapping what it read, "
        "of {:.3f} s",
        served_->name(), served_->seconds(), server.mapping_seconds(), summary_.wall_seconds);
    return;
  }
  Stopwatch wall;
  const bool resume = !options_.resume_dir.empty();
  fs::path resume_file;
  if (resume) {
    resume_file = newest_restart_file();
    if (const std::string why = restart_blocker(); !why.empty())
      throw Error("cannot resume from " + resume_file.string() + ": " + why);
  }
  // A resumed run changes nothing in its folder before the restart file has been read and
  // accepted (read_restart_file() below); a new run prepares the folder here.
  if (!resume) {
    Stopwatch clock;  // the output folder and an earlier run's VTK files: output time
    fs::create_directories(output_dir_ / "vtk");
    if (const int removed = remove_pvd_series(output_dir_ / "vtk"); removed > 0)
      logger->info("removed {} VTK files of an earlier run from {}", removed,
                   (output_dir_ / "vtk").string());
    summary_.output_seconds += clock.seconds();
  }

  open_csv_files();
  progress_ = Progress{};
  progress_.next_output = output_every_;
  if (!resume) {
    flush_csv_files();  // the headers
  } else {
    read_restart_file(resume_file, progress_);
    fs::create_directories(output_dir_ / "vtk");
    summary_.resumed_from = progress_.windows_done;
  }
  write_plot_requests();

  logger->info(
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
      resume ? fmt::format("; resumed after window {} from {}", progress_.windows_done,
                           resume_file.filename().string())
             : std::string());

  // The run advances window by window; all else it does after a window is an observer's
  // (window_observer.hpp, case_run_observers.cpp), also for the initial state (window 0).
  const std::vector<std::unique_ptr<WindowObserver>> observers = window_observers();
  auto notify = [&](FinishedWindow& w) {
    for (const auto& o : observers) o->observe(w);
  };
  ProgressLine progress_line(window_count_);
  try {
    if (!resume) {
      scheme_->initialize();
      FinishedWindow initial;
      notify(initial);
    }
    for (std::int64_t n = progress_.windows_done; n < window_count_; ++n) {
      const TimeWindow window(window_size_, n, 1);
      const WindowReport r = scheme_->advance(window);
      progress_.windows_done = n + 1;
      summary_.windows = n + 1;
      summary_.iterations += r.iterations;
      summary_.max_window_iterations = std::max(summary_.max_window_iterations, r.iterations);
      if (!r.converged) ++summary_.unconverged_windows;
      FinishedWindow w;
      w.window = n + 1;
      w.time = window.end();
      w.report = &r;
      w.last = n + 1 == window_count_;
      notify(w);
      progress_line.update(n + 1, w.time, r.iterations);
      if (w.signal != 0) {
        summary_.stopped_by_signal = w.signal;
        progress_line.finish();
        logger->warn("stopped by signal {} after window {} (t = {:.6g} s){}", w.signal, n + 1,
                     w.time,
                     summary_.last_restart.empty()
                         ? std::string()
                         : "; continue with: partita run CASE --resume " + output_dir_.string());
        break;
      }
    }
  } catch (...) {
    progress_line.finish();
    flush_csv_files();  // the complete rows so far stay readable
    throw;
  }
  progress_line.finish();
  scheme_->stop_threads();  // the participants' threads (a concurrent parallel scheme)
  flush_csv_files();
  Stopwatch close_clock;
  coupling_csv_.close();
  for (auto& m : monitors_) m.csv.close();
  if (energy_) energy_csv_.close();
  summary_.output_seconds += close_clock.seconds();
  for (auto& p : participants_) {
    Stopwatch sc;
    p->finalize();
    p->add_seconds(sc.seconds());
  }

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
      "{:.3f} s, "
      "output {:.3f} s, core {:.3f} s{}{}",
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
  if (energy_) {
    // The windows the tolerance reads: those whose energy reached energy.floor.
    const double floor = energy_->settings().floor;
    const std::string below =
        summary_.energy_balance_uncounted
            ? fmt::format("; {} windows whose energy stayed below energy.floor {:.3g} J not "
                          "counted",
                          summary_.energy_balance_uncounted, floor)
            : std::string();
    if (summary_.max_energy_balance_window < 0)
      logger->info("energy balance: no window's energy reached energy.floor {:.3g} J, nothing "
                   "to read",
                   floor);
    else
      logger->info("energy balance: largest |error| {:.3g} at t = {:.6g} s (window {}){}{}",
                   summary_.max_energy_balance_error, summary_.max_energy_balance_time,
                   summary_.max_energy_balance_window,
                   summary_.energy_balance_warnings
                       ? fmt::format("; {} windows beyond energy.tolerance {:.3g}",
                                     summary_.energy_balance_warnings,
                                     energy_->settings().tolerance)
                       : std::string(),
                   below);
  }
}

}  // namespace partita::run
