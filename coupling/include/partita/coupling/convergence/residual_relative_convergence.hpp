#pragma once
// |x^k - x^{k-1}|_2 / |x^1 - x^0|_2 <= limit: the residual relative to the first residual of
// the window (a first residual of zero counts as converged).

#include "partita/coupling/convergence/convergence_measure.hpp"

namespace partita::coupling {

class ResidualRelativeConvergence : public ConvergenceMeasure {
 public:
  using ConvergenceMeasure::ConvergenceMeasure;
  std::string name() const override { return "residual-relative"; }
  static std::unique_ptr<ConvergenceMeasure> create(const config::Node& node);

 protected:
  double compute(const Eigen::VectorXd& previous, const Eigen::VectorXd& current) override;
  void reset() override { first_ = 0.0; }

 private:
  double first_ = 0.0;
};

}  // namespace partita::coupling
