#pragma once
// |x^k - x^{k-1}|_2 / |x^k|_2 <= limit   (preCICE's relative-convergence-measure; a zero
// difference counts as converged even when x^k = 0)

#include "partita/coupling/convergence/convergence_measure.hpp"

namespace partita::coupling {

class RelativeConvergence : public ConvergenceMeasure {
 public:
  using ConvergenceMeasure::ConvergenceMeasure;
  std::string name() const override { return "relative"; }
  static std::unique_ptr<ConvergenceMeasure> create(const config::Node& node);

 protected:
  double compute(const Eigen::VectorXd& previous, const Eigen::VectorXd& current) override;
};

}  // namespace partita::coupling
