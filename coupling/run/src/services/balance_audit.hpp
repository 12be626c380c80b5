#pragma once
// The balance audit: per audited exchange (extensive data, or data on weighted points at both
// ends), what arrived after mapping against what was sent, |received total - sent total| / scale,
// after each window; a warning the first time one exceeds coupling.balance_tolerance (later ones
// are counted in the summary). Its values go to coupling.csv and let the health check skip the
// exchanges whose totals were finite.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "partita/coupling/exchange.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class BalanceAudit final : public Service {
 public:
  BalanceAudit(std::vector<const coupling::Exchange*> audited, double tolerance);

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "balance audit"; }
  void serialize(StateArchive& ar) override;
  void report(RunSummary& summary) const override;

  const std::vector<const coupling::Exchange*>& audited() const { return audited_; }
  /// This window's relative imbalance per audited exchange (in the order of audited()).
  const std::vector<double>& imbalance() const { return imbalance_; }
  /// Whether this window's totals of that exchange were finite (then its values are: a NaN or an
  /// infinity makes a total NaN or infinite); false for an exchange that is not audited.
  bool finite(const coupling::Exchange& e) const;

 private:
  void compute();  // into imbalance_ and finite_

  std::vector<const coupling::Exchange*> audited_;
  double tolerance_;
  std::int64_t warnings_ = 0;  // windows over the tolerance (restart files keep it)
  bool warned_ = false;
  std::vector<double> imbalance_;  // the result and scratch space, kept between windows (no
  Eigen::VectorXd sent_, received_;  // allocation per window)
  Eigen::ArrayXd norm_;
  std::vector<char> finite_;
  std::vector<Eigen::VectorXd> bounds_;  // per audited exchange: W^T omega (or empty)
};

}  // namespace partita::run
