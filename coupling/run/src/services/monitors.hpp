#pragma once
// The monitors (the case's `monitors` list): per monitor DIR/<name>.csv, a row per window of the
// quantities it names, and DIR/<name>.plots, the plots the plot script draws from it. Each
// participant is asked once per window for every quantity any monitor (or the energy balance)
// needs; a non-finite value stops the run (it is diverging). Where each column finds its value:
// (participant slot, position in what the solver returned), the position remembered from the last
// window and checked by name (no search per window unless a solver changes its answer's order).
// A monitor with `every: N` records the initial state, every N-th window and the last; the
// participants are asked only in windows where a monitor (or the energy balance, its own
// `every`) records, so the non-finite check then runs in those windows (a diverging solver's
// own state checks, HealthCheck, still run every window).

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "partita/coupling/participant.hpp"
#include "partita/interface/output.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class Monitors final : public Service {
 public:
  struct Monitor {
    std::string name;
    std::vector<std::pair<coupling::Participant*, std::string>> quantities;
    std::vector<std::vector<std::string>> plots;  // monitor.plots: x, then its y
    int every = 1;  // a row every this many windows (and the initial state and the last window)
  };
  /// `extra`: quantities asked with the same request whose values extra_values() gives (the
  /// energy balance's terms), in the windows where extra_due() says so (extra_every).
  Monitors(const std::filesystem::path& output_dir, std::vector<Monitor> monitors,
           std::vector<std::pair<coupling::Participant*, std::string>> extra,
           int extra_every = 1);

  /// Whether a series sampled every `every` windows records window w (the initial state, every
  /// `every`-th window, the last).
  static bool due(const coupling::FinishedWindow& w, int every) {
    return every <= 1 || w.window % every == 0 || w.last;
  }
  /// Whether this window's extra values were asked (extra_values() holds them).
  bool extra_due(const coupling::FinishedWindow& w) const { return due(w, extra_every_); }

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "monitors"; }
  void serialize(StateArchive& ar) override;
  void restored() override;
  void start(bool resumed) override;
  void flush() override;
  void finish(bool failed) override;
  void report(RunSummary& summary) const override;

  /// This window's values of the extra quantities, in their order.
  void extra_values(std::vector<double>& out) const { values_of(columns_of_.back(), out); }

 private:
  struct Asked {
    coupling::Participant* p;
    std::vector<std::string> names;
    std::vector<MonitorValue> values;
  };
  struct Column {
    std::size_t asked;
    const std::string* name;
    mutable std::size_t at = 0;  // where it was found last
  };
  void ask(std::size_t list, const std::pair<coupling::Participant*, std::string>& pq);
  void values_of(const std::vector<Column>& cols, std::vector<double>& out) const;
  void write_plot_requests() const;

  std::filesystem::path output_dir_;
  std::vector<Monitor> monitors_;
  std::vector<std::pair<coupling::Participant*, std::string>> extra_;
  int extra_every_ = 1;
  std::vector<CsvSeries> csv_;  // per monitor
  std::vector<Asked> wanted_;
  std::vector<std::vector<Column>> columns_of_;  // per monitor, then the extra quantities
  std::vector<double> row_;
  std::vector<std::pair<std::string, std::string>> restored_;  // (name, CSV text) read back
  double seconds_ = 0.0;  // output time
};

}  // namespace partita::run
