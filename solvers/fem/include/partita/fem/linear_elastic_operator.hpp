#pragma once
#include "partita/fem/internal_force_operator.hpp"

namespace partita::fem {

// f_int = K u with a stiffness K assembled once (Hex8 incompatible modes included); no history.
// The matrix is referenced, not copied: it must outlive the operator.
class LinearElasticOperator final : public InternalForceOperator {
 public:
  explicit LinearElasticOperator(const SparseMatrix& k) : k_(k) {}
  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k) override;
  void commit() override {}
  const SparseMatrix* constant_tangent() const override { return &k_; }
  // eps |(|K| |u|)| of the last evaluate(): the bound of the error of the sum K u.
  double round_off() const override;
  double strain_energy() const override { return energy_; }
  double plastic_work() const override { return 0.0; }
  const std::vector<double>& committed_state() const override { return empty_; }
  void set_committed_state(const std::vector<double>& state) override;

 private:
  const SparseMatrix& k_;
  double energy_ = 0.0;
  Eigen::VectorXd u_;  // the u of the last evaluate() (for round_off(), computed on demand)
  std::vector<double> empty_;
};

}  // namespace partita::fem
