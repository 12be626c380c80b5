#include "monitors.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;
namespace fs = std::filesystem;

Monitors::Monitors(const fs::path& output_dir, std::vector<Monitor> monitors,
                   std::vector<std::pair<Participant*, std::string>> extra, int extra_every)
    : output_dir_(output_dir),
      monitors_(std::move(monitors)),
      extra_(std::move(extra)),
      extra_every_(extra_every),
      columns_of_(monitors_.size() + 1) {
  for (const auto& m : monitors_) {
    std::vector<std::pair<std::string, std::string>> mc;
    for (const auto& [p, q] : m.quantities) {
      std::string unit;  // only that quantity: monitors() would compute every one (energies)
      for (const auto& v : p->monitor_values({q}))
        if (v.name == q) unit = v.unit;
      mc.emplace_back(p->name() + "." + q, unit);
    }
    csv_.emplace_back(output_dir_ / (m.name + ".csv"), "time", "s", mc);
  }
  // the monitors' columns, then the extra quantities (asked with the same request)
  for (std::size_t mi = 0; mi < monitors_.size(); ++mi)
    for (const auto& pq : monitors_[mi].quantities) ask(mi, pq);
  for (const auto& pq : extra_) ask(monitors_.size(), pq);
}

void Monitors::ask(std::size_t list, const std::pair<Participant*, std::string>& pq) {
  const auto& p = pq.first;  // not a structured binding: clang 14 cannot capture those
  const auto& q = pq.second;
  auto it = std::find_if(wanted_.begin(), wanted_.end(), [&](const Asked& a) { return a.p == p; });
  if (it == wanted_.end()) it = wanted_.insert(wanted_.end(), Asked{p, {}, {}});
  it->names.push_back(q);
  columns_of_[list].push_back({static_cast<std::size_t>(it - wanted_.begin()), &q});
}

void Monitors::values_of(const std::vector<Column>& cols, std::vector<double>& out) const {
  out.clear();
  for (const Column& c : cols) {
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

void Monitors::observe(FinishedWindow& w) {
  // sampled series (every > 1): nothing is asked in a window that none records
  bool any = !extra_.empty() && extra_due(w);
  for (const Monitor& m : monitors_) any = any || due(w, m.every);
  if (!any) return;
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
  for (std::size_t mi = 0; mi < monitors_.size(); ++mi) {
    if (!due(w, monitors_[mi].every)) continue;
    values_of(columns_of_[mi], row_);
    Stopwatch csv_clock;  // formatting the row: output time, not the core's
    csv_[mi].record(w.time, row_);
    seconds_ += csv_clock.seconds();
  }
}

// The monitors' count is written (a restart file names each), each checked against the case.
void Monitors::serialize(StateArchive& ar) {
  auto count = static_cast<std::uint64_t>(monitors_.size());
  ar.io(count);
  if (!ar.reading()) {
    for (std::size_t i = 0; i < monitors_.size(); ++i) {
      ar.io(monitors_[i].name);
      ar.io(csv_[i].text());
    }
    return;
  }
  if (count > monitors_.size() + 1000)  // (a count no case has: damaged bytes)
    ar.fail(fmt::format("{} monitors (found {})", monitors_.size(), count));
  restored_.resize(count);
  for (auto& [monitor, text] : restored_) {
    ar.io(monitor);
    ar.io(text);
  }
  // A resumed run goes on writing the rows of the monitors it had (their rows so far are in the
  // restart): other monitors, or other columns of one, would join rows of another width to its
  // header. Refused, saying what changed.
  const auto names = [](const auto& list, auto name_of) {
    std::string n;
    for (const auto& m : list) n += (n.empty() ? "" : ", ") + name_of(m);
    return n;
  };
  if (restored_.size() != monitors_.size())
    throw Error(fmt::format(
        "the case has {} monitors ({}), the run being resumed had {} ({}): a resumed run keeps "
        "its monitors as they were (time and output may change, the monitors' list not); start "
        "a new run for other monitors",
        monitors_.size(), names(monitors_, [](const Monitor& m) { return m.name; }),
        restored_.size(), names(restored_, [](const auto& r) { return r.first; })));
  for (std::size_t i = 0; i < monitors_.size(); ++i) {
    if (restored_[i].first != monitors_[i].name) ar.fail("the monitor '" + monitors_[i].name + "'");
    const auto header = [](const std::string& text) { return text.substr(0, text.find('\n')); };
    const std::string now = header(csv_[i].text()), then = header(restored_[i].second);
    if (now != then)
      throw Error(fmt::format(
          "the monitor '{}' asks for other quantities than in the run being resumed (its columns "
          "then: {}; now: {}): a resumed run keeps its monitors' columns; start a new run for "
          "other quantities",
          monitors_[i].name, then, now));
  }
}

void Monitors::restored() {
  for (std::size_t i = 0; i < monitors_.size(); ++i)
    csv_[i].restore_text(std::move(restored_[i].second));
  restored_.clear();
}

void Monitors::start(bool resumed) {
  if (!resumed) flush();  // the headers
  write_plot_requests();
}

// The monitors' plots against another quantity (monitors[].plots), one line each: x, then its
// y, as the CSV's column names without their units. plot_monitors.py reads DIR/<name>.plots
// beside DIR/<name>.csv; a monitor without plots has no such file.
void Monitors::write_plot_requests() const {
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

void Monitors::flush() {
  Stopwatch clock;
  for (auto& c : csv_) c.flush();
  seconds_ += clock.seconds();
}

void Monitors::finish(bool failed) {
  flush();
  if (failed) return;
  Stopwatch clock;
  for (auto& c : csv_) c.close();
  seconds_ += clock.seconds();
}

void Monitors::report(RunSummary& summary) const { summary.output_seconds += seconds_; }

}  // namespace partita::run
