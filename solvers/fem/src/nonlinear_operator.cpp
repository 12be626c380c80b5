#include "partita/fem/nonlinear_operator.hpp"

#include <algorithm>
#include <string>

#include "contribution_list.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {

NonlinearOperator::NonlinearOperator(const Model& model)
    : mesh_(model.mesh()), assembler_(std::make_unique<BlockAssembler>(model.mesh())) {
  auto material = std::make_unique<MaterialContribution>(model);
  material_ = material.get();
  contributions_.push_back(std::move(material));
}

NonlinearOperator::~NonlinearOperator() = default;

void NonlinearOperator::add_contribution(std::unique_ptr<OperatorContribution> contribution) {
  detail::add_contribution(contributions_, assembler_, mesh_, pattern_fixed_, std::move(contribution),
                           "nonlinear operator");
}

void NonlinearOperator::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int,
                                 SparseMatrix* k) {
  f_int.setZero(u.size());
  if (k != nullptr) {
    for (const auto& c : contributions_) {
      if (!c->has_tangent()) {
        throw Error("nonlinear operator: contribution '" + std::string(c->name()) +
                    "' has no tangent: it works in central-difference (explicit) analyses only");
      }
    }
    if (k->nonZeros() == 0) *k = assembler_->make_matrix();
    pattern_fixed_ = true;
    std::fill(k->valuePtr(), k->valuePtr() + k->nonZeros(), 0.0);
  }
  // f = sum_c f_c(u);  K = sum_c K_c(u)
  for (const auto& c : contributions_) c->add(u, f_int, k, *assembler_);
}

void NonlinearOperator::commit() {
  for (const auto& c : contributions_) c->commit();
}

double NonlinearOperator::round_off() const {
  double r = 0.0;
  for (const auto& c : contributions_) r += c->round_off();
  return r;
}

double NonlinearOperator::strain_energy() const {
  double w = 0.0;
  for (const auto& c : contributions_) w += c->stored_energy();
  return w;
}

double NonlinearOperator::plastic_work() const {
  double w = 0.0;
  for (const auto& c : contributions_) w += c->dissipated_work();
  return w;
}

const std::vector<double>& NonlinearOperator::committed_state() const {
  if (contributions_.size() == 1) return material_->committed_state();
  gather_committed_states(contributions_, state_);
  return state_;
}

void NonlinearOperator::set_committed_state(const std::vector<double>& state) {
  if (contributions_.size() == 1) {
    material_->set_committed_state(state);
    return;
  }
  scatter_committed_states(contributions_, state, "nonlinear operator");
}

}  // namespace partita::fem
