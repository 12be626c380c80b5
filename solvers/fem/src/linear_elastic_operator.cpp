#include "partita/fem/linear_elastic_operator.hpp"

#include <limits>

#include "partita/fem/error.hpp"

namespace partita::fem {

void LinearElasticOperator::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int,
                                     SparseMatrix* k) {
  // f_int = K u;  W = 1/2 u^T K u
  f_int.noalias() = k_ * u;
  energy_ = 0.5 * u.dot(f_int);
  u_ = u;
  if (k != nullptr) *k = k_;
}

double LinearElasticOperator::round_off() const {
  if (u_.size() != k_.cols()) return 0.0;
  // eps sum_j |K_ij| |u_j| per row: the rounding bound of each row's sum
  const Eigen::VectorXd a = k_.cwiseAbs() * u_.cwiseAbs();
  return std::numeric_limits<double>::epsilon() * a.norm();
}

void LinearElasticOperator::set_committed_state(const std::vector<double>& state) {
  if (!state.empty()) {
    throw Error("linear elastic operator: a history of " + std::to_string(state.size()) +
                " values was given, this model has none (state of another model?)");
  }
}

}  // namespace partita::fem
