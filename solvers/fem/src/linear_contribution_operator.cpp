#include "partita/fem/linear_contribution_operator.hpp"

#include <algorithm>
#include <string>

#include "contribution_list.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {

LinearContributionOperator::LinearContributionOperator(const SparseMatrix& k, const Mesh& mesh)
    : k_(k), mesh_(mesh), linear_(k), assembler_(std::make_unique<BlockAssembler>(mesh)) {}

LinearContributionOperator::~LinearContributionOperator() = default;

void LinearContributionOperator::add_contribution(std::unique_ptr<OperatorContribution> contribution) {
  detail::add_contribution(contributions_, assembler_, mesh_, pattern_fixed_, std::move(contribution),
                           "linear operator");
}

void LinearContributionOperator::map_stiffness(const SparseMatrix& tangent) {
  // K's pattern (the mesh's node adjacency) is contained in the tangent's, column by column,
  // both with sorted row indices
  if (!k_.isCompressed() || k_.rows() != tangent.rows() || k_.cols() != tangent.cols())
    throw Error("linear operator: the stiffness matrix does not match the tangent's pattern");
  slot_.resize(static_cast<std::size_t>(k_.nonZeros()));
  for (Eigen::Index j = 0; j < k_.outerSize(); ++j) {
    Eigen::Index p = tangent.outerIndexPtr()[j];
    const Eigen::Index end = tangent.outerIndexPtr()[j + 1];
    for (Eigen::Index i = k_.outerIndexPtr()[j]; i < k_.outerIndexPtr()[j + 1]; ++i) {
      while (p < end && tangent.innerIndexPtr()[p] < k_.innerIndexPtr()[i]) ++p;
      if (p == end || tangent.innerIndexPtr()[p] != k_.innerIndexPtr()[i])
        throw Error("linear operator: an entry of K lies outside the tangent's pattern");
      slot_[static_cast<std::size_t>(i)] = p;
    }
  }
}

void LinearContributionOperator::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int,
                                          SparseMatrix* k) {
  if (k != nullptr) {
    for (const auto& c : contributions_) {
      if (!c->has_tangent()) {
        throw Error("linear operator: contribution '" + std::string(c->name()) +
                    "' has no tangent: it works in central-difference (explicit) analyses only");
      }
    }
    if (k->nonZeros() == 0) *k = assembler_->make_matrix();
    if (!pattern_fixed_) map_stiffness(*k);
    pattern_fixed_ = true;
    // K_t = K, then the contributions' K_c added below
    std::fill(k->valuePtr(), k->valuePtr() + k->nonZeros(), 0.0);
    const double* kv = k_.valuePtr();
    double* tv = k->valuePtr();
    for (std::size_t i = 0; i < slot_.size(); ++i) tv[slot_[i]] = kv[i];
  }
  // f = K u + sum_c f_c(u)
  linear_.evaluate(u, f_int, nullptr);
  for (const auto& c : contributions_) c->add(u, f_int, k, *assembler_);
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
