#include "energy_balance_service.hpp"

#include <cmath>

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;

EnergyBalanceService::EnergyBalanceService(const std::filesystem::path& file,
                                           std::unique_ptr<EnergyBalance> balance,
                                           const Monitors& monitors, const EnergyAudit& audit)
    : balance_(std::move(balance)),
      monitors_(monitors),
      audit_(audit),
      csv_(file, "time", "s", balance_->columns()) {}

void EnergyBalanceService::observe(FinishedWindow& w) {
  if (!monitors_.extra_due(w)) return;  // (energy.every: a sampled balance, its terms cumulative)
  const double created = audit_.created();  // the interfaces' net created energy
  monitors_.extra_values(terms_);
  EnergyBalance& balance = *balance_;
  const EnergyBalance::Row b = balance.evaluate(terms_, created, row_);
  Stopwatch csv_clock;
  csv_.record(w.time, row_);
  seconds_ += csv_clock.seconds();
  if (!balance.counts(b)) {
    ++totals_.uncounted;  // below energy.floor: not read, as by the tolerance
  } else if (totals_.max_window < 0 || std::abs(b.error) > totals_.max_error) {
    totals_.max_error = std::abs(b.error);
    totals_.max_time = w.time;
    totals_.max_window = w.window;
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
  if (totals_.warnings++ == 0)
    log::get("coupling")->warn("{}; further windows are counted in the summary", what);
}

void EnergyBalanceService::Totals::serialize(StateArchive& ar) {
  ar.io(warnings);
  ar.io(max_error);
  ar.io(max_time);
  ar.io(max_window);
  ar.io(uncounted);
}

// [u8 started] [f64 initial] the totals [text energy.csv]
void EnergyBalanceService::serialize(StateArchive& ar) {
  if (ar.reading()) {
    ar.io(restored_.started);
    ar.io(restored_.initial);
    restored_.totals.serialize(ar);
    ar.io(restored_.csv);
    // A run that started without an energy section starts its balance at the restart (its
    // initial value is then that window's); one that had it must have had the same columns.
    const auto header = [](const std::string& text) { return text.substr(0, text.find('\n')); };
    if (!restored_.csv.empty() && header(restored_.csv) != header(csv_.text()))
      throw Error(fmt::format(
          "the restart file's run started with another energy section (energy.csv columns: {}; "
          "now: {}): resume with the energy section it started with",
          header(restored_.csv), header(csv_.text())));
    return;
  }
  auto started = static_cast<std::uint8_t>(balance_->started() ? 1 : 0);
  ar.io(started);
  const double initial = balance_->initial();
  ar.io(initial);
  totals_.serialize(ar);
  ar.io(csv_.text());
}

void EnergyBalanceService::skip(StateArchive& ar) {
  Restored r;
  ar.io(r.started);
  ar.io(r.initial);
  r.totals.serialize(ar);
  ar.io(r.csv);
}

void EnergyBalanceService::restored() {
  totals_ = restored_.totals;
  if (restored_.csv.empty()) return;  // started without an energy section: starts here
  balance_->restore(restored_.started != 0, restored_.initial);
  csv_.restore_text(std::move(restored_.csv));
}

void EnergyBalanceService::start(bool resumed) {
  if (!resumed) flush();  // the header
}

void EnergyBalanceService::flush() {
  Stopwatch clock;
  csv_.flush();
  seconds_ += clock.seconds();
}

void EnergyBalanceService::finish(bool failed) {
  flush();
  if (failed) return;
  Stopwatch clock;
  csv_.close();
  seconds_ += clock.seconds();
}

void EnergyBalanceService::report(RunSummary& summary) const {
  summary.output_seconds += seconds_;
  summary.energy_balance_warnings = static_cast<long>(totals_.warnings);
  summary.max_energy_balance_error = totals_.max_error;
  summary.max_energy_balance_time = totals_.max_time;
  summary.max_energy_balance_window = totals_.max_window;
  summary.energy_balance_uncounted = static_cast<long>(totals_.uncounted);
}

void EnergyBalanceService::log_summary() const {
  auto logger = log::get("coupling");
  // The windows the tolerance reads: those whose energy reached energy.floor.
  const double floor = balance_->settings().floor;
  const std::string below =
      totals_.uncounted
          ? fmt::format("; {} windows whose energy stayed below energy.floor {:.3g} J not counted",
                        totals_.uncounted, floor)
          : std::string();
  if (totals_.max_window < 0)
    logger->info("energy balance: no window's energy reached energy.floor {:.3g} J, nothing to read",
                 floor);
  else
    logger->info("energy balance: largest |error| {:.3g} at t = {:.6g} s (window {}){}{}",
                 totals_.max_error, totals_.max_time, totals_.max_window,
                 totals_.warnings ? fmt::format("; {} windows beyond energy.tolerance {:.3g}",
                                                totals_.warnings, balance_->settings().tolerance)
                                  : std::string(),
                 below);
}

}  // namespace partita::run
