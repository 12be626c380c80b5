#include "partita/fem/linear_contribution_operator.hpp"

#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

LinearContributionOperator::LinearContributionOperator(const SparseMatrix& k, const Mesh& mesh)
    : linear_(k), assembler_(mesh) {}

void LinearContributionOperator::add_contribution(std::unique_ptr<OperatorContribution> contribution) {
  if (!contribution) throw Error("linear operator: a null contribution was added");
  contributions_.push_back(std::move(contribution));
}

void LinearContributionOperator::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int,
                                          SparseMatrix* k) {
  if (k != nullptr) {
    throw Error(
        "the linear path with contributions (a rigid indenter) runs central difference only; "
        "static and Newmark analyses with contributions take the nonlinear path");
  }
  // f = K u + sum_c f_c(u)
  linear_.evaluate(u, f_int, nullptr);
  for (const auto& c : contributions_) c->add(u, f_int, nullptr, assembler_);
}

void LinearContributionOperator::commit() {
  for (const auto& c : contributions_) c->commit();
}

void LinearContributionOperator::set_time(double t, double fraction) {
  for (const auto& c : contributions_) c->set_time(t, fraction);
}

double LinearContributionOperator::round_off() const {
  double r = linear_.round_off();
  for (const auto& c : contributions_) r += c->round_off();
  return r;
}

double LinearContributionOperator::strain_energy() const {
  double w = linear_.strain_energy();
  for (const auto& c : contributions_) w += c->stored_energy();
  return w;
}

double LinearContributionOperator::plastic_work() const {
  double w = 0.0;
  for (const auto& c : contributions_) w += c->dissipated_work();
  return w;
}

double LinearContributionOperator::max_frequency_squared(const Eigen::VectorXd& nodal_mass) const {
  double w2 = 0.0;
  for (const auto& c : contributions_) w2 += c->max_frequency_squared(nodal_mass);
  return w2;
}

const std::vector<double>& LinearContributionOperator::committed_state() const {
  gather_committed_states(contributions_, state_);
  return state_;
}

void LinearContributionOperator::set_committed_state(const std::vector<double>& state) {
  scatter_committed_states(contributions_, state, "linear operator");
}

}  // namespace partita::fem
