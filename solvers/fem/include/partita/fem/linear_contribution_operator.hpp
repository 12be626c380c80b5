#pragma once
#include <cstddef>
#include <memory>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/linear_elastic_operator.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem {

// The linear path's operator with contributions beside K u (a rigid indenter's contact):
//   f_int(u) = K u + sum_c f_c(u),   K_t(u) = K + sum_c K_c(u),
// K the assembled linear-elastic stiffness (referenced, as LinearElasticOperator does), so the
// material part stays one sparse product per evaluation. Its tangent is not constant (a contact
// opens and closes), so it offers none (constant_tangent() is nullptr): static and Newmark
// analyses take Newton on it, central difference needs f_int alone. The tangent's sparsity
// pattern is the mesh's node adjacency plus the node groups the contributions declare
// (OperatorContribution::coupled_node_groups()); K's values are copied into it at each tangent
// evaluation. Energies, round-off and the committed state are the sums / concatenation of
// K u's and the contributions'.
class LinearContributionOperator final : public InternalForceOperator {
 public:
  LinearContributionOperator(const SparseMatrix& k, const Mesh& mesh);
  ~LinearContributionOperator() override;
  // One that couples nodes beyond the mesh's elements must come before the first tangent is
  // assembled (the pattern is fixed then).
  void add_contribution(std::unique_ptr<OperatorContribution> contribution);
  std::size_t num_contributions() const { return contributions_.size(); }

  // f = K u + sum_c f_c(u); K_t as well when k != nullptr (every contribution must offer one).
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
  // K's entries in the tangent's pattern: K_t.valuePtr()[slot_[i]] += K.valuePtr()[i]
  void map_stiffness(const SparseMatrix& tangent);
  const SparseMatrix& k_;
  const Mesh& mesh_;
  LinearElasticOperator linear_;
  std::unique_ptr<BlockAssembler> assembler_;
  std::vector<std::unique_ptr<OperatorContribution>> contributions_;
  std::vector<Eigen::Index> slot_;
  bool pattern_fixed_ = false;  // a tangent has been assembled with assembler_'s pattern
  mutable std::vector<double> state_;
};

}  // namespace partita::fem
