// CaseRun, the observers of a finished window (window_observer.hpp): each of what a run does after
// a window, in the order window_observers() builds them. They keep the run's state in CaseRun's
// members (restart files save it there) and only the bookkeeping of their own between windows.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "partita/run/case_run.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace {
// The energy audit acts when the coupling has created more than the tolerated share of the work
// that passed for this many windows in a row: the lag of the explicit schemes makes single
// windows exceed it when a contact starts (the granules landing on an FE floor, a plate reaching
// the granules: 1-2 windows at up to 100 %, of 1e-14..1e-8 J), while an unstable coupling keeps
// creating energy window after window, its share growing towards 1 (the undamped rubber plate of
// README.md's energy audit reaches two thirds of the work after 300 windows). The
// stable seed-000 cases stay below 0.2 (0.08-0.2 over the first 10 windows, < 0.02 after 100).
constexpr int kEnergyAuditWindows = 20;
}  // namespace

// What arrived against what was sent, per audited exchange (into imbalance_ and audit_finite_,
// which the health check and coupling.csv read); a warning the first time one is off.
class CaseRun::BalanceAuditObserver : public WindowObserver {
 public:
  explicit BalanceAuditObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    if (w.initial()) return;
    const std::vector<double>& imbalance = run_.audit_balance();
    for (std::size_t i = 0; i < imbalance.size(); ++i)
      if (imbalance[i] > run_.balance_tolerance_) {
        ++run_.summary_.imbalance_warnings;
        if (!warned_)
          log::get("coupling")
              ->warn(
                  "window {} (t = {:.6g} s): exchange {} arrives off by {:.3g} of what was sent "
                  "(coupling.balance_tolerance {:.3g}); the mapper does not conserve its total: "
                  "use a conservative constraint or mapper (area-balanced for tractions); further "
                  "windows are counted in the summary",
                  w.window, w.time, run_.audited_[i]->label(), imbalance[i],
                  run_.balance_tolerance_);
        warned_ = true;
      }
  }

 private:
  CaseRun& run_;
  bool warned_ = false;
};

// Non-finite exchanged values and each solver's own check (stops the run with a diagnosis).
class CaseRun::HealthCheckObserver : public WindowObserver {
 public:
  explicit HealthCheckObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    // after the balance audit: where its totals are finite, the values need not be read again
    run_.check_window(w.window, w.time, !w.initial());
  }

 private:
  CaseRun& run_;
};

// coupling.csv: the window's iterations, residuals, imbalances and the interfaces' work.
class CaseRun::CouplingCsvObserver : public WindowObserver {
 public:
  explicit CouplingCsvObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    if (w.initial()) return;
    const WindowReport& r = *w.report;
    row_.assign({w.time, static_cast<double>(r.iterations)});  // keeps its capacity
    row_.insert(row_.end(), r.residuals.begin(), r.residuals.end());
    row_.insert(row_.end(), run_.imbalance_.begin(), run_.imbalance_.end());
    for (const auto& p : run_.energy_pairs_) {
      const EnergyAudit a = run_.audit_energy(p);
      row_.insert(row_.end(), {a.on_a, a.on_b, a.created()});
    }
    Stopwatch csv_clock;
    run_.coupling_csv_.record(static_cast<double>(w.window), row_);
    run_.summary_.output_seconds += csv_clock.seconds();
  }

 private:
  CaseRun& run_;
  std::vector<double> row_;
};

// The monitors' CSV files (and the energy balance's terms): the quantities each participant
// must report, asked for once per window, and where each column finds its value: (participant
// slot, position in what the solver returned), the position remembered from the last window and
// checked by name (no search per window unless a solver changes the order of its answer).
class CaseRun::MonitorObserver : public WindowObserver {
 public:
  explicit MonitorObserver(CaseRun& run) : run_(run), columns_of_(run.monitors_.size() + 1) {
    // the monitors' columns, then the energy balance's terms (asked with the same request)
    for (std::size_t mi = 0; mi < run_.monitors_.size(); ++mi)
      for (const auto& pq : run_.monitors_[mi].quantities) ask(mi, pq);
    if (run_.energy_)
      for (const auto& pq : run_.energy_terms_) ask(run_.monitors_.size(), pq);
  }

  void observe(FinishedWindow& w) override {
    for (Asked& a : wanted_) {
      Stopwatch clock;  // the solver computes its quantities: its time, not the core's
      a.values = a.p->monitor_values(a.names);
      a.p->add_seconds(clock.seconds());
      for (const auto& mv : a.values)
        if (!std::isfinite(mv.value))
          throw Error(fmt::format(
              "window {} (t = {:.6g} s): participant '{}' reports {} = {} {}: the run is "
              "diverging; reduce time.window or the substep size, add damping, or check the "
              "materials and loads",
              w.window, w.time, a.p->name(), mv.name, mv.value, mv.unit));
    }
    for (std::size_t mi = 0; mi < run_.monitors_.size(); ++mi) {
      values_of(columns_of_[mi], row_);
      Stopwatch csv_clock;  // formatting the row: output time, not the core's
      run_.monitors_[mi].csv.record(w.time, row_);
      run_.summary_.output_seconds += csv_clock.seconds();
    }
  }

  /// This window's values of the energy balance's terms, in its order.
  void energy_terms(std::vector<double>& out) { values_of(columns_of_.back(), out); }

 private:
  struct Asked {
    Participant* p;
    std::vector<std::string> names;
    std::vector<MonitorValue> values;
  };
  struct Column {
    std::size_t asked;
    const std::string* name;
    std::size_t at = 0;
  };

  void ask(std::size_t list, const std::pair<Participant*, std::string>& pq) {
    const auto& p = pq.first;  // not a structured binding: clang 14 cannot capture those
    const auto& q = pq.second;
    auto it =
        std::find_if(wanted_.begin(), wanted_.end(), [&](const Asked& a) { return a.p == p; });
    if (it == wanted_.end()) it = wanted_.insert(wanted_.end(), Asked{p, {}, {}});
    it->names.push_back(q);
    columns_of_[list].push_back({static_cast<std::size_t>(it - wanted_.begin()), &q});
  }

  void values_of(std::vector<Column>& cols, std::vector<double>& out) {
    out.clear();
    for (Column& c : cols) {
      const std::vector<MonitorValue>& got = wanted_[c.asked].values;
      if (c.at >= got.size() || got[c.at].name != *c.name) {
        // the last value of that name, as the search before (NaN where the solver gave none)
        c.at = got.size();
        for (std::size_t k = 0; k < got.size(); ++k)
          if (got[k].name == *c.name) c.at = k;
      }
      out.push_back(c.at < got.size() ? got[c.at].value : std::nan(""));
    }
  }

  CaseRun& run_;
  std::vector<Asked> wanted_;
  std::vector<std::vector<Column>> columns_of_;  // per monitor, then the energy balance's terms
  std::vector<double> row_;
};

// The energy balance of the whole system (energy.csv): the terms the monitors' request brought,
// the interfaces' created energy; a warning or a stop beyond its tolerance.
class CaseRun::EnergyBalanceObserver : public WindowObserver {
 public:
  EnergyBalanceObserver(CaseRun& run, MonitorObserver& monitors)
      : run_(run), monitors_(monitors) {}
  void observe(FinishedWindow& w) override {
    const double created = run_.coupling_created();  // the interfaces' net created energy
    monitors_.energy_terms(terms_);
    EnergyBalance& balance = *run_.energy_;
    const EnergyBalance::Row b = balance.evaluate(terms_, created, row_);
    Stopwatch csv_clock;
    run_.energy_csv_.record(w.time, row_);
    run_.summary_.output_seconds += csv_clock.seconds();
    RunSummary& sum = run_.summary_;
    if (!balance.counts(b)) {
      ++sum.energy_balance_uncounted;  // below energy.floor: not read, as by the tolerance
    } else if (sum.max_energy_balance_window < 0 ||
               std::abs(b.error) > sum.max_energy_balance_error) {
      sum.max_energy_balance_error = std::abs(b.error);
      sum.max_energy_balance_time = w.time;
      sum.max_energy_balance_window = w.window;
    }
    if (!balance.exceeded(b)) return;
    const std::string what = fmt::format(
        "window {} (t = {:.6g} s): the energy balance is off by {:.3g} (energy.tolerance "
        "{:.3g}): {}{}; check that the energy section names every input, store and loss of the "
        "system, and the exchanges (the balance audit in coupling.csv)",
        w.window, w.time, b.error, balance.settings().tolerance, balance.describe(b),
        balance.settings().coupling_column && !balance.settings().count_coupling
            ? fmt::format("; the coupling created {:.4g} J of it", created)
            : std::string());
    if (balance.settings().stop) throw Error(what);
    if (run_.summary_.energy_balance_warnings++ == 0)
      log::get("coupling")->warn("{}; further windows are counted in the summary", what);
  }

 private:
  CaseRun& run_;
  MonitorObserver& monitors_;
  std::vector<double> terms_, row_;
};

// The energy audit of each pair of participants that read from each other: the energy the
// coupling created against the work that passed, acting after coupling.csv and the monitors have
// their row of the window (a run it stops keeps them).
class CaseRun::EnergyAuditObserver : public WindowObserver {
 public:
  explicit EnergyAuditObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    if (w.initial()) return;
    for (auto& p : run_.energy_pairs_) {
      const EnergyAudit a = run_.audit_energy(p);
      p.passed += std::abs(a.on_a - p.last_a) + std::abs(a.on_b - p.last_b);
      p.last_a = a.on_a;
      p.last_b = a.on_b;
      p.over = a.created() > run_.energy_tolerance_ * p.passed ? p.over + 1 : 0;
      if (p.over < kEnergyAuditWindows) continue;
      const std::string what = fmt::format(
          "window {} (t = {:.6g} s): the coupling between '{}' and '{}' has created {:.4g} J, "
          "{:.0f} % of the {:.4g} J that passed through their interface (work on '{}' {:.4g} J, "
          "on '{}' {:.4g} J; a lossless interface creates none), more than "
          "coupling.energy_tolerance {:.3g} for {} windows in a row: the coupled run is "
          "unstable; shorten time.window, add damping to the structure (e.g. "
          "analysis.rayleigh.beta) or use an implicit scheme",
          w.window, w.time, p.a->name(), p.b->name(), a.created(), 100.0 * a.created() / p.passed,
          p.passed, p.a->name(), a.on_a, p.b->name(), a.on_b, run_.energy_tolerance_,
          kEnergyAuditWindows);
      if (run_.energy_stop_) throw Error(what);
      if (run_.summary_.energy_warnings++ == 0)
        log::get("coupling")->warn("{}; further windows are counted in the summary", what);
    }
  }

 private:
  CaseRun& run_;
};

// VTK frames: the initial state, every output.every and the last window.
class CaseRun::VtkObserver : public WindowObserver {
 public:
  explicit VtkObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    Progress& pr = run_.progress_;
    const double every = run_.output_every_, window = run_.window_size_;
    if (w.initial()) {
      run_.write_output(pr.frame++, 0.0);
      return;
    }
    if ((every > 0.0 && TimeWindow::reached(w.time, pr.next_output, window)) || w.last) {
      run_.write_output(pr.frame++, w.time);
      while (every > 0.0 && TimeWindow::reached(w.time, pr.next_output, window))
        pr.next_output = static_cast<double>(pr.frame) * every;
    }
  }

 private:
  CaseRun& run_;
};

// A signal to this process or to another participant's: every participant is told, and the
// window carries it to the restart files and the run's end.
class CaseRun::StopRequestObserver : public WindowObserver {
 public:
  explicit StopRequestObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    if (w.initial()) return;
    int signal = run_.options_.stop_signal ? run_.options_.stop_signal->load() : 0;
    for (const auto& p : run_.participants_)  // a signal to another participant's process
      if (signal == 0) signal = p->stop_request();
    if (signal != 0)
      for (const auto& p : run_.participants_) p->note_stop(signal);
    w.signal = signal;
  }

 private:
  CaseRun& run_;
};

// Restart files: every N windows, every T minutes, after the last window, and on a signal.
class CaseRun::RestartObserver : public WindowObserver {
 public:
  explicit RestartObserver(CaseRun& run) : run_(run), blocker_(run.restart_blocker()) {}
  void observe(FinishedWindow& w) override {
    if (w.initial()) return;
    const bool due = (run_.restart_every_windows_ > 0 &&
                      w.window % run_.restart_every_windows_ == 0) ||
                     (run_.restart_every_seconds_ > 0.0 &&
                      since_restart_.seconds() >= run_.restart_every_seconds_) ||
                     (w.last && run_.restart_at_end_) || w.signal != 0;
    if (!due) return;
    if (blocker_.empty()) {
      run_.write_restart_file(run_.progress_);
      since_restart_.restart();
    } else if (w.signal != 0) {
      log::get("coupling")->warn("no restart file: {}", blocker_);
    }
  }

 private:
  CaseRun& run_;
  const std::string blocker_;
  Stopwatch since_restart_;
};

// CSV files are rewritten whole at each flush (always complete on disk): flush every 2 s, or
// less often once a flush takes longer than 2 % of the interval (very long runs).
class CaseRun::FlushObserver : public WindowObserver {
 public:
  explicit FlushObserver(CaseRun& run) : run_(run) {}
  void observe(FinishedWindow& w) override {
    if (w.initial() || since_flush_.seconds() <= interval_) return;
    Stopwatch flush_clock;
    run_.flush_csv_files();
    interval_ = std::max(2.0, 50.0 * flush_clock.seconds());
    since_flush_.restart();
  }

 private:
  CaseRun& run_;
  Stopwatch since_flush_;
  double interval_ = 2.0;  // [s]
};

std::vector<std::unique_ptr<WindowObserver>> CaseRun::window_observers() {
  std::vector<std::unique_ptr<WindowObserver>> o;
  o.push_back(std::make_unique<BalanceAuditObserver>(*this));
  o.push_back(std::make_unique<HealthCheckObserver>(*this));
  o.push_back(std::make_unique<CouplingCsvObserver>(*this));
  auto monitors = std::make_unique<MonitorObserver>(*this);
  MonitorObserver& m = *monitors;
  o.push_back(std::move(monitors));
  if (energy_) o.push_back(std::make_unique<EnergyBalanceObserver>(*this, m));
  o.push_back(std::make_unique<EnergyAuditObserver>(*this));
  o.push_back(std::make_unique<VtkObserver>(*this));
  o.push_back(std::make_unique<StopRequestObserver>(*this));
  o.push_back(std::make_unique<RestartObserver>(*this));
  o.push_back(std::make_unique<FlushObserver>(*this));
  return o;
}

}  // namespace partita::run
