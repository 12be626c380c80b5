#pragma once
#include <cstddef>
#include <memory>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/material_contribution.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem {

// The FE operator of the nonlinear path: a sum of contributions (as MFEM's NonlinearForm sums
// its integrators),
//   f(u) = sum_c f_c(u),   K(u) = sum_c K_c(u),
// the first of them the material's internal force (MaterialContribution: element by element
// from the material laws, see there); others (a rigid indenter's contact, a spring bed ...)
// join with add_contribution() before the first evaluate(). The time integrators and the
// Newton solver see only the sum (InternalForceOperator): a new contribution touches neither.
// The tangent's sparsity pattern is the mesh's node adjacency plus the node groups the
// contributions declare (OperatorContribution::coupled_node_groups()).
// Energies: strain_energy() sums the contributions' stored energies, plastic_work() their
// dissipated work; the committed state is the contributions' states one after the other (the
// material's first, so a model without other contributions has the material's state only).
class NonlinearOperator final : public InternalForceOperator {
 public:
  explicit NonlinearOperator(const Model& model);
  ~NonlinearOperator() override;

  // Adds a contribution (after the material's). One that couples nodes beyond the mesh's
  // elements must come before the first tangent is assembled (the pattern is fixed then).
  void add_contribution(std::unique_ptr<OperatorContribution> contribution);
  std::size_t num_contributions() const { return contributions_.size(); }
  const OperatorContribution& contribution(std::size_t i) const { return *contributions_.at(i); }

  // f = sum_c f_c(u); K = sum_c K_c(u) when k != nullptr (every contribution must offer one).
  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k) override;
  void commit() override;
  void set_time(double t, double fraction) override {
    for (const auto& c : contributions_) c->set_time(t, fraction);
  }
  double round_off() const override;
  double strain_energy() const override;
  double plastic_work() const override;
  const std::vector<double>& committed_state() const override;
  void set_committed_state(const std::vector<double>& state) override;

  // The material's contribution and its per-point results (see MaterialContribution).
  const MaterialContribution& material() const { return *material_; }
  MaterialContribution& material() { return *material_; }
  std::size_t num_quadrature_points() const { return material_->num_quadrature_points(); }
  bool fbar_hex8() const { return material_->fbar_hex8(); }
  const MatrixX6& cauchy_stress() const { return material_->cauchy_stress(); }
  const Eigen::VectorXd& equivalent_plastic_strain() const {
    return material_->equivalent_plastic_strain();
  }
  const std::vector<std::size_t>& element_qp_offsets() const {
    return material_->element_qp_offsets();
  }

 private:
  const Mesh& mesh_;
  MaterialContribution* material_ = nullptr;  // contributions_[0]
  std::vector<std::unique_ptr<OperatorContribution>> contributions_;
  std::unique_ptr<BlockAssembler> assembler_;
  bool pattern_fixed_ = false;         // a tangent has been assembled with assembler_'s pattern
  mutable std::vector<double> state_;  // committed_state() of several contributions
};

}  // namespace partita::fem
