#pragma once
#include <memory>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/linear_elastic_operator.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem {

// The linear path's explicit operator with contributions beside K u (a rigid indenter's contact):
//   f_int(u) = K u + sum_c f_c(u),
// K the assembled linear-elastic stiffness (referenced, as LinearElasticOperator does), so the
// material part stays one sparse product per step. Central difference only: it offers no tangent
// (the linear path's static and Newmark solves factorise K once; a model that needs contributions
// there takes the nonlinear path, SolverOptions::nonlinear_path). Energies, round-off and the
// committed state are the sums / concatenation of K u's and the contributions'.
class LinearContributionOperator final : public InternalForceOperator {
 public:
  LinearContributionOperator(const SparseMatrix& k, const Mesh& mesh);
  void add_contribution(std::unique_ptr<OperatorContribution> contribution);

  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k) override;
  void commit() override;
  void set_time(double t, double fraction) override;
  double round_off() const override;
  double strain_energy() const override;
  double plastic_work() const override;
  const std::vector<double>& committed_state() const override;
  void set_committed_state(const std::vector<double>& state) override;
  // sum of the contributions' bounds (OperatorContribution::max_frequency_squared)
  double max_frequency_squared(const Eigen::VectorXd& nodal_mass) const;

 private:
  LinearElasticOperator linear_;
  BlockAssembler assembler_;  // add()'s signature; no tangent is assembled
  std::vector<std::unique_ptr<OperatorContribution>> contributions_;
  mutable std::vector<double> state_;
};

}  // namespace partita::fem
