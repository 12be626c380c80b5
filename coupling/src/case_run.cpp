#include "partita/coupling/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/progress_line.hpp"
#include "partita/coupling/remote_participant.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/coupling/sweep.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::coupling {

// The energy audit acts when the coupling has created more than the tolerated share of the work
// that passed for this many windows in a row: the lag of the explicit schemes makes single
// windows exceed it when a contact starts (the granules landing on an FE floor, a plate reaching
// the granules: 1-2 windows at up to 100 %, of 1e-14..1e-8 J), while an unstable coupling keeps
// creating energy (the undamped rubber plate: 0.66 at window 300, 0.92-0.97 from 500 on). The
// stable seed-000 cases stay below 0.2 (0.08-0.2 over the first 10 windows, < 0.02 after 100).
constexpr int kEnergyAuditWindows = 20;

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

void CaseRun::run() {
  if (options_.check_only) return;
  auto logger = log::get("coupling");
  if (serves()) {  // the controller runs the windows; this process answers for its participant
    Stopwatch wall;
    ParticipantServer server(*options_.distributed.controller, options_.stop_signal);
    summary_.stopped_by_signal = server.serve(*served_);
    summary_.wall_seconds = wall.seconds();
    summary_.participant_seconds.emplace_back(served_->name(), served_->seconds());
    logger->info("participant '{}' served the run: {:.3f} s in its solver of {:.3f} s",
                 served_->name(), served_->seconds(), summary_.wall_seconds);
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
  // The quantities each participant must report, asked for once per window, and where each
  // monitor column finds its value: (participant slot, position in what the solver returned),
  // the position remembered from the last window and checked by name (no search per window
  // unless a solver changes the order of its answer).
  struct Asked {
    Participant* p;
    std::vector<std::string> names;
    std::vector<MonitorValue> values;
  };
  std::vector<Asked> wanted;
  struct Column {
    std::size_t asked;
    const std::string* name;
    std::size_t at = 0;
  };
  // the monitors' columns, then the energy balance's terms (asked with the same request)
  std::vector<std::vector<Column>> columns_of(monitors_.size() + (energy_ ? 1 : 0));
  auto ask = [&](std::size_t list, const std::pair<Participant*, std::string>& pq) {
    const auto& p = pq.first;  // not a structured binding: clang 14 cannot capture those
    const auto& q = pq.second;
    auto it = std::find_if(wanted.begin(), wanted.end(), [&](const Asked& a) { return a.p == p; });
    if (it == wanted.end()) it = wanted.insert(wanted.end(), Asked{p, {}, {}});
    it->names.push_back(q);
    columns_of[list].push_back({static_cast<std::size_t>(it - wanted.begin()), &q});
  };
  for (std::size_t mi = 0; mi < monitors_.size(); ++mi)
    for (const auto& pq : monitors_[mi].quantities) ask(mi, pq);
  if (energy_)
    for (const auto& pq : energy_terms_) ask(monitors_.size(), pq);
  std::vector<double> monitor_row, energy_row;
  auto values_of = [&](std::vector<Column>& cols, std::vector<double>& out) {
    out.clear();
    for (Column& c : cols) {
      const std::vector<MonitorValue>& got = wanted[c.asked].values;
      if (c.at >= got.size() || got[c.at].name != *c.name) {
        // the last value of that name, as the search before (NaN where the solver gave none)
        c.at = got.size();
        for (std::size_t k = 0; k < got.size(); ++k)
          if (got[k].name == *c.name) c.at = k;
      }
      out.push_back(c.at < got.size() ? got[c.at].value : std::nan(""));
    }
  };
  // coupling_created: the interfaces' net created energy [J] (the energy audit's pairs)
  auto record_monitors = [&](double t, std::int64_t window, double coupling_created) {
    for (Asked& a : wanted) {
      Stopwatch clock;  // the solver computes its quantities: its time, not the core's
      a.values = a.p->monitor_values(a.names);
      a.p->add_seconds(clock.seconds());
      for (const auto& mv : a.values)
        if (!std::isfinite(mv.value))
          throw Error(fmt::format(
              "window {} (t = {:.6g} s): participant '{}' reports {} = {} {}: the run is "
              "diverging; reduce time.window or the substep size, add damping, or check the "
              "materials and loads",
              window, t, a.p->name(), mv.name, mv.value, mv.unit));
    }
    for (std::size_t mi = 0; mi < monitors_.size(); ++mi) {
      values_of(columns_of[mi], monitor_row);
      Stopwatch csv_clock;  // formatting the row: output time, not the core's
      monitors_[mi].csv.record(t, monitor_row);
      summary_.output_seconds += csv_clock.seconds();
    }
    if (!energy_) return;
    values_of(columns_of.back(), monitor_row);
    const EnergyBalance::Row b = energy_->evaluate(monitor_row, coupling_created, energy_row);
    Stopwatch csv_clock;
    energy_csv_.record(t, energy_row);
    summary_.output_seconds += csv_clock.seconds();
    summary_.max_energy_balance_error =
        std::max(summary_.max_energy_balance_error, std::abs(b.error));
    if (!energy_->exceeded(b)) return;
    const std::string what = fmt::format(
        "window {} (t = {:.6g} s): the energy balance is off by {:.3g} (energy.tolerance {:.3g}): "
        "{}{}; check that the energy section names every input, store and loss of the system, "
        "and the exchanges (the balance audit in coupling.csv)",
        window, t, b.error, energy_->settings().tolerance, energy_->describe(b),
        energy_->settings().coupling_column && !energy_->settings().count_coupling
            ? fmt::format("; the coupling created {:.4g} J of it", coupling_created)
            : std::string());
    if (energy_->settings().stop) throw Error(what);
    if (summary_.energy_balance_warnings++ == 0)
      logger->warn("{}; further windows are counted in the summary", what);
  };
  auto flush_all = [&] {
    Stopwatch clock;
    coupling_csv_.flush();
    for (auto& m : monitors_) m.csv.flush();
    if (energy_) energy_csv_.flush();
    summary_.output_seconds += clock.seconds();
  };

  Progress progress;
  progress.next_output = output_every_;
  if (!resume) {
    flush_all();  // the headers
  } else {
    read_restart_file(resume_file, progress);
    fs::create_directories(output_dir_ / "vtk");
    summary_.resumed_from = progress.windows_done;
  }

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
      resume ? fmt::format("; resumed after window {} from {}", progress.windows_done,
                           resume_file.filename().string())
             : std::string());

  const std::string blocker = restart_blocker();
  ProgressLine progress_line(window_count_);
  Stopwatch since_flush, since_restart;
  double flush_interval = 2.0;  // [s]
  bool warned_imbalance = false;
  try {
    if (!resume) {
      scheme_->initialize();
      check_window(0, 0.0);
      record_monitors(0.0, 0, energy_ ? coupling_created() : 0.0);
      write_output(progress.frame++, 0.0);
    }
    TimeWindow window(window_size_, 0, 1);
    std::vector<double> row;  // coupling.csv's row of the window
    std::vector<EnergyAudit> audits;  // of the energy audit's pairs, this window
    for (std::int64_t n = progress.windows_done; n < window_count_; ++n) {
      window = TimeWindow(window_size_, n, 1);
      const WindowReport r = scheme_->advance(window);
      const double t = window.end();
      progress.windows_done = n + 1;
      summary_.windows = n + 1;
      summary_.iterations += r.iterations;
      summary_.max_window_iterations = std::max(summary_.max_window_iterations, r.iterations);
      if (!r.converged) ++summary_.unconverged_windows;
      // the audit first: where its totals are finite, the check need not read the values again
      const std::vector<double>& imbalance = audit_balance();
      check_window(n + 1, t, true);
      row.assign({t, static_cast<double>(r.iterations)});  // keeps its capacity
      row.insert(row.end(), r.residuals.begin(), r.residuals.end());
      row.insert(row.end(), imbalance.begin(), imbalance.end());
      audits.clear();
      double created = 0.0;
      for (const auto& p : energy_pairs_) {
        audits.push_back(audit_energy(p));
        created += audits.back().created();
      }
      for (std::size_t pi = 0; pi < energy_pairs_.size(); ++pi) {
        EnergyPair& p = energy_pairs_[pi];
        const EnergyAudit a = audits[pi];
        row.insert(row.end(), {a.on_a, a.on_b, a.created()});
        p.passed += std::abs(a.on_a - p.last_a) + std::abs(a.on_b - p.last_b);
        p.last_a = a.on_a;
        p.last_b = a.on_b;
        p.over = a.created() > energy_tolerance_ * p.passed ? p.over + 1 : 0;
        if (p.over < kEnergyAuditWindows) continue;
        const std::string what = fmt::format(
            "window {} (t = {:.6g} s): the coupling between '{}' and '{}' has created {:.4g} J, "
            "{:.0f} % of the {:.4g} J that passed through their interface (work on '{}' {:.4g} J, "
            "on '{}' {:.4g} J; a lossless interface creates none), more than "
            "coupling.energy_tolerance {:.3g} for {} windows in a row: the coupled run is "
            "unstable; shorten time.window, add damping to the structure (e.g. "
            "analysis.rayleigh.beta) or use an implicit scheme",
            n + 1, t, p.a->name(), p.b->name(), a.created(), 100.0 * a.created() / p.passed,
            p.passed, p.a->name(), a.on_a, p.b->name(), a.on_b, energy_tolerance_,
            kEnergyAuditWindows);
        if (energy_stop_) {
          coupling_csv_.record(static_cast<double>(n + 1), row);
          record_monitors(t, n + 1, created);
          throw Error(what);
        }
        if (summary_.energy_warnings++ == 0)
          logger->warn("{}; further windows are counted in the summary", what);
      }
      for (std::size_t i = 0; i < imbalance.size(); ++i)
        if (imbalance[i] > balance_tolerance_) {
          ++summary_.imbalance_warnings;
          if (!warned_imbalance)
            logger->warn(
                "window {} (t = {:.6g} s): exchange {} arrives off by {:.3g} of what was sent "
                "(coupling.balance_tolerance {:.3g}); the mapper does not conserve its total: use "
                "a conservative constraint or mapper (area-balanced for tractions); further "
                "windows are counted in the summary",
                n + 1, t, audited_[i]->label(), imbalance[i], balance_tolerance_);
          warned_imbalance = true;
        }
      Stopwatch csv_clock;
      coupling_csv_.record(static_cast<double>(n + 1), row);
      summary_.output_seconds += csv_clock.seconds();
      record_monitors(t, n + 1, created);
      const bool last = n + 1 == window_count_;
      if ((output_every_ > 0.0 && TimeWindow::reached(t, progress.next_output, window_size_)) ||
          last) {
        write_output(progress.frame++, t);
        while (output_every_ > 0.0 && TimeWindow::reached(t, progress.next_output, window_size_))
          progress.next_output = static_cast<double>(progress.frame) * output_every_;
      }
      int signal = options_.stop_signal ? options_.stop_signal->load() : 0;
      for (const auto& p : participants_)  // a signal to another participant's process
        if (signal == 0) signal = p->stop_request();
      if (signal != 0)
        for (const auto& p : participants_) p->note_stop(signal);
      const bool restart_due =
          (restart_every_windows_ > 0 && (n + 1) % restart_every_windows_ == 0) ||
          (restart_every_seconds_ > 0.0 && since_restart.seconds() >= restart_every_seconds_) ||
          (last && restart_at_end_) || signal != 0;
      if (restart_due) {
        if (blocker.empty()) {
          write_restart_file(progress);
          since_restart.restart();
        } else if (signal != 0) {
          logger->warn("no restart file: {}", blocker);
        }
      }
      // CSV files are rewritten whole at each flush (always complete on disk): flush every 2 s,
      // or less often once a flush takes longer than 2 % of the interval (very long runs)
      if (since_flush.seconds() > flush_interval) {
        Stopwatch flush_clock;
        flush_all();
        flush_interval = std::max(2.0, 50.0 * flush_clock.seconds());
        since_flush.restart();
      }
      progress_line.update(n + 1, t, r.iterations);
      if (signal != 0) {
        summary_.stopped_by_signal = signal;
        progress_line.finish();
        logger->warn("stopped by signal {} after window {} (t = {:.6g} s){}", signal, n + 1, t,
                     summary_.last_restart.empty()
                         ? std::string()
                         : "; continue with: partita run CASE --resume " + output_dir_.string());
        break;
      }
    }
  } catch (...) {
    progress_line.finish();
    flush_all();  // the complete rows so far stay readable
    throw;
  }
  progress_line.finish();
  flush_all();
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
  summary_.core_seconds = std::max(0.0, summary_.wall_seconds - accounted);

  for (const auto& p : participants_)
    if (const std::string t = p->transport_summary(); !t.empty())
      logger->info("participant '{}' in another process: {}", p->name(), t);
  std::string parts;
  for (const auto& [n, s] : summary_.participant_seconds)
    parts += fmt::format("{} {:.3f} s, ", n, s);
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
  if (energy_)
    logger->info("energy balance: largest |error| {:.3g}{}", summary_.max_energy_balance_error,
                 summary_.energy_balance_warnings
                     ? fmt::format(", {} windows beyond energy.tolerance {:.3g}",
                                   summary_.energy_balance_warnings, energy_->settings().tolerance)
                     : std::string());
}

}  // namespace partita::coupling
