#pragma once
// DIR/coupling.csv: per window its iterations, the scheme's residuals, the balance audit's
// imbalances and, per pair of the energy audit, the work through their interface and the energy
// the coupling created.

#include <filesystem>
#include <vector>

#include "balance_audit.hpp"
#include "energy_audit.hpp"
#include "partita/coupling/coupling_scheme.hpp"
#include "partita/interface/output.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class CouplingCsv final : public Service {
 public:
  CouplingCsv(const std::filesystem::path& file, const coupling::CouplingScheme& scheme,
              const BalanceAudit& balance, const EnergyAudit& energy);

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "coupling.csv"; }
  void serialize(StateArchive& ar) override;
  void restored() override;
  void start(bool resumed) override;
  void flush() override;
  void finish(bool failed) override;
  void report(RunSummary& summary) const override;

 private:
  const BalanceAudit& balance_;
  const EnergyAudit& energy_;
  CsvSeries csv_;
  std::vector<double> row_;
  std::string restored_;  // the text a restart file held
  double seconds_ = 0.0;  // output time
};

}  // namespace partita::run
