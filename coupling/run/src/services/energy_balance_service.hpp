#pragma once
// The energy balance of the whole system (the case's `energy` section; energy_balance.hpp does
// the arithmetic): DIR/energy.csv, a row per window of the terms the monitors' request brought
// and the energy the coupling created (the energy audit's), and a warning or a stop where the
// balance is off by more than energy.tolerance. Its largest error, over the windows whose energy
// reached energy.floor, goes to the summary.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "energy_audit.hpp"
#include "monitors.hpp"
#include "partita/coupling/energy_balance.hpp"
#include "partita/interface/output.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class EnergyBalanceService final : public Service {
 public:
  /// `terms` are the extra quantities of `monitors`, in the balance's order.
  EnergyBalanceService(const std::filesystem::path& file,
                       std::unique_ptr<coupling::EnergyBalance> balance, const Monitors& monitors,
                       const EnergyAudit& audit);

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "energy balance"; }
  void serialize(StateArchive& ar) override;
  void without_section(const std::string& file) override {}  // started afresh at the restart
  void restored() override;
  void start(bool resumed) override;
  void flush() override;
  void finish(bool failed) override;
  void report(RunSummary& summary) const override;
  void log_summary() const override;

  /// A restart file's section of a run without an energy section (format 5 kept one): read and
  /// dropped.
  static void skip(StateArchive& ar);

 private:
  // what restart files keep besides the CSV text
  struct Totals {
    std::int64_t warnings = 0;
    double max_error = 0.0;      // the largest |error| of the windows that count
    double max_time = -1.0;      // and when it occurred (-1: no window counted yet)
    std::int64_t max_window = -1;
    std::int64_t uncounted = 0;  // windows below energy.floor
    void serialize(StateArchive& ar);
  };
  std::unique_ptr<coupling::EnergyBalance> balance_;
  const Monitors& monitors_;
  const EnergyAudit& audit_;
  CsvSeries csv_;
  Totals totals_;
  std::vector<double> terms_, row_;
  double seconds_ = 0.0;  // output time
  // a restart file's section, applied by restored()
  struct Restored {
    std::uint8_t started = 0;
    double initial = 0.0;
    Totals totals;
    std::string csv;
  } restored_;
};

}  // namespace partita::run
