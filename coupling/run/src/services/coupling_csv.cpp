#include "coupling_csv.hpp"

#include "partita/coupling/stopwatch.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;

CouplingCsv::CouplingCsv(const std::filesystem::path& file, const CouplingScheme& scheme,
                         const BalanceAudit& balance, const EnergyAudit& energy)
    : balance_(balance), energy_(energy) {
  std::vector<std::pair<std::string, std::string>> columns = {{"time", "s"}, {"iterations", ""}};
  for (const auto& c : scheme.residual_columns()) columns.push_back(c);
  for (const Exchange* e : balance.audited()) columns.emplace_back("imbalance " + e->label(), "");
  for (const auto& p : energy.pairs()) {
    columns.emplace_back("work on " + p.a->name() + " by " + p.b->name(), "J");
    columns.emplace_back("work on " + p.b->name() + " by " + p.a->name(), "J");
    columns.emplace_back("energy created " + p.label, "J");
  }
  csv_ = CsvSeries(file, "window", "", columns);
}

void CouplingCsv::observe(FinishedWindow& w) {
  if (w.initial()) return;
  const WindowReport& r = *w.report;
  row_.assign({w.time, static_cast<double>(r.iterations)});  // keeps its capacity
  row_.insert(row_.end(), r.residuals.begin(), r.residuals.end());
  row_.insert(row_.end(), balance_.imbalance().begin(), balance_.imbalance().end());
  for (std::size_t i = 0; i < energy_.pairs().size(); ++i) {
    const EnergyAudit::Work a = energy_.work(i);
    row_.insert(row_.end(), {a.on_a, a.on_b, a.created()});
  }
  Stopwatch csv_clock;
  csv_.record(static_cast<double>(w.window), row_);
  seconds_ += csv_clock.seconds();
}

void CouplingCsv::serialize(StateArchive& ar) {
  if (ar.reading())
    ar.io(restored_);
  else
    ar.io(csv_.text());
}

void CouplingCsv::restored() { csv_.restore_text(std::move(restored_)); }

void CouplingCsv::start(bool resumed) {
  if (!resumed) flush();  // the header
}

void CouplingCsv::flush() {
  Stopwatch clock;
  csv_.flush();
  seconds_ += clock.seconds();
}

void CouplingCsv::finish(bool failed) {
  flush();
  if (failed) return;
  Stopwatch clock;
  csv_.close();
  seconds_ += clock.seconds();
}

void CouplingCsv::report(RunSummary& summary) const { summary.output_seconds += seconds_; }

}  // namespace partita::run
