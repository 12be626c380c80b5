#include "partita/coupling/convergence/absolute_convergence.hpp"

namespace partita::coupling {

double AbsoluteConvergence::compute(const Eigen::VectorXd& previous,
                                    const Eigen::VectorXd& current) {
  // |x^k - x^{k-1}|
  return (current - previous).norm();
}

std::unique_ptr<ConvergenceMeasure> AbsoluteConvergence::create(const config::Node& node) {
  return std::make_unique<AbsoluteConvergence>(node.string("data"), node.real("limit"));
}

}  // namespace partita::coupling
