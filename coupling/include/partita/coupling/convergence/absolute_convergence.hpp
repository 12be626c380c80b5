#pragma once
// |x^k - x^{k-1}|_2 <= limit   (in the data's unit)

#include "partita/coupling/convergence/convergence_measure.hpp"

namespace partita::coupling {

class AbsoluteConvergence : public ConvergenceMeasure {
 public:
  using ConvergenceMeasure::ConvergenceMeasure;
  std::string name() const override { return "absolute"; }
  bool dimensionless() const override { return false; }
  static std::unique_ptr<ConvergenceMeasure> create(const config::Node& node);

 protected:
  double compute(const Eigen::VectorXd& previous, const Eigen::VectorXd& current) override;
};

}  // namespace partita::coupling
