#include "partita/coupling/convergence/residual_relative_convergence.hpp"

namespace partita::coupling {

double ResidualRelativeConvergence::compute(const Eigen::VectorXd& previous,
                                            const Eigen::VectorXd& current) {
  // |x^k - x^{k-1}| / |x^1 - x^0|
  const double diff = (current - previous).norm();
  if (iteration() == 1) first_ = diff;
  if (diff == 0.0) return 0.0;
  return first_ > 0.0 ? diff / first_ : 0.0;
}

std::unique_ptr<ConvergenceMeasure> ResidualRelativeConvergence::create(const config::Node& node) {
  return std::make_unique<ResidualRelativeConvergence>(node.string("data"), node.real("limit"));
}

}  // namespace partita::coupling
