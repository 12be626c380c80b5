#pragma once
#include <cstddef>
#include <memory>
#include <vector>

#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/model.hpp"

namespace partita::fem {

class BlockAssembler;

// Total Lagrangian internal force and tangent, element by element from the material laws:
//   F = I + sum_a u_a (x) grad_X N_a,   f_a,i = int_Omega0 P_iJ(F, history) dN_a/dX_J dV,
//   K_(a i)(b k) = int_Omega0 dN_a/dX_J A_iJkL dN_b/dX_L dV.
// Small-strain laws return sigma(sym(F - I)) as P, which makes this the linear-geometry
// operator for them. Quadrature: the full (stiffness) rule of each element (Hex8 2x2x2, Hex20
// 3x3x3, Tet4 1, Tet10 4 points); plain displacement elements (no incompatible modes, no
// F-bar): use Hex20 or Tet10 for bending of thin parts and for near-incompressible flow.
// Regions without a law use a LinearElasticLaw of their Material.
class NonlinearOperator final : public InternalForceOperator {
 public:
  explicit NonlinearOperator(const Model& model);
  ~NonlinearOperator() override;

  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k) override;
  void commit() override { committed_ = trial_; }
  double strain_energy() const override { return energy_; }
  double plastic_work() const override;
  const std::vector<double>& committed_state() const override { return committed_; }
  void set_committed_state(const std::vector<double>& state) override;

  std::size_t num_quadrature_points() const { return weight_.size(); }
  // Per quadrature point, at the last evaluate(): Cauchy stress sigma = P F^T / J (Voigt xx yy
  // zz xy yz zx) and the equivalent plastic strain of the trial history.
  const MatrixX6& cauchy_stress() const { return cauchy_; }
  const Eigen::VectorXd& equivalent_plastic_strain() const { return eqps_; }
  // Elements' first quadrature point index (num_elements + 1 entries).
  const std::vector<std::size_t>& element_qp_offsets() const { return qp_offset_; }

 private:
  const Mesh& mesh_;
  std::vector<std::shared_ptr<const MaterialLaw>> region_laws_;
  std::vector<const MaterialLaw*> element_law_;
  std::vector<std::size_t> qp_offset_;        // per element
  std::vector<std::size_t> state_offset_;     // per quadrature point (+1)
  std::vector<double> gradients_;             // per qp: n x 3 dN/dX, row-major
  std::vector<std::size_t> gradient_offset_;  // per qp: start in gradients_
  std::vector<double> weight_;                // per qp: det J w
  std::vector<double> committed_, trial_;
  double energy_ = 0.0;
  MatrixX6 cauchy_;
  Eigen::VectorXd eqps_;
  std::unique_ptr<BlockAssembler> assembler_;
};

}  // namespace partita::fem
