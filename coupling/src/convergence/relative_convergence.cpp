#include "partita/coupling/convergence/relative_convergence.hpp"

#include <limits>

namespace partita::coupling {

double RelativeConvergence::compute(const Eigen::VectorXd& previous,
                                    const Eigen::VectorXd& current) {
  // |x^k - x^{k-1}| / |x^k|
  const double diff = (current - previous).norm();
  if (diff == 0.0) return 0.0;
  const double norm = current.norm();
  return norm > 0.0 ? diff / norm : std::numeric_limits<double>::infinity();
}

std::unique_ptr<ConvergenceMeasure> RelativeConvergence::create(const config::Node& node) {
  return std::make_unique<RelativeConvergence>(node.string("data"), node.real("limit"));
}

}  // namespace partita::coupling
