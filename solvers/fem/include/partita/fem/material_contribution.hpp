#pragma once
#include <cstddef>
#include <memory>
#include <vector>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/failure_criterion.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem {

// The material's contribution to the FE operator of the nonlinear path (NonlinearOperator sums
// it with the others): total Lagrangian internal force and tangent, element by element from the
// material laws, with the history of every quadrature point:
//   F = I + sum_a u_a (x) grad_X N_a,   f_a,i = int_Omega0 P_iJ(F, history) dN_a/dX_J dV,
//   K_(a i)(b k) = int_Omega0 dN_a/dX_J A_iJkL dN_b/dX_L dV.
// Small-strain laws return sigma(sym(F - I)) as P, which makes this the linear-geometry
// operator for them. Quadrature: the full (stiffness) rule of each element (Hex8 2x2x2, Hex20
// 3x3x3, Tet4 1, Tet10 4 points). Plain displacement elements unless the model's Hex8
// formulation is FBar; plain Hex8 locks in bending of thin parts and near-incompressible flow.
// Regions without a law use a LinearElasticLaw of their Material.
//
// Element formulations, one file each, beside what they share (material_contribution.cpp: set-up,
// assembly, commit, rupture; material_contribution_kernels.hpp: the point-level pieces):
//   material_contribution_full.cpp     full integration (every element but the Hex8 variants)
//   material_contribution_eas.cpp      EAS Hex8 (Hex8Formulation::IncompatibleModes, the default)
//   material_contribution_fbar.cpp     F-bar Hex8 (Hex8Formulation::FBar)
//   material_contribution_reduced.cpp  reduced Hex8 with hourglass control (Hex8Formulation::Reduced,
//                                      central difference only)
// Each file opens with its formulation's equations and references.
class MaterialContribution final : public OperatorContribution {
 public:
  explicit MaterialContribution(const Model& model);
  ~MaterialContribution() override;

  std::string_view name() const override { return "material"; }
  void add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
           const BlockAssembler& assembler) override;
  // committed = trial (copied in blocks by the OpenMP threads)
  void commit() override;
  // The time of the next add()s: rate-dependent laws read the time since the committed state
  // (MaterialStep::time_increment); fraction 0 is the committed state itself, at t.
  void set_time(double t, double fraction) override {
    if (fraction == 0.0) committed_time_ = t;
    trial_time_ = fraction == 0.0   ? t
                  : fraction == 1.0 ? t
                                    : committed_time_ + fraction * (t - committed_time_);
    step_.time_increment = trial_time_ - committed_time_;
  }
  // Whether the next add()s belong to a dynamic analysis (rate terms of the laws on, see
  // MaterialStep); StructuralSolver sets it for each analysis; off (static) until then.
  void set_dynamic(bool dynamic) { step_.dynamic = dynamic; }
  const MaterialStep& step() const { return step_; }
  double round_off() const override { return round_off_; }
  // int W dV at the u of the last add()
  double stored_energy() const override { return energy_; }
  // plastic work int w_p dV of the committed history
  double dissipated_work() const override;
  const std::vector<double>& committed_state() const override { return committed_; }
  void set_committed_state(const std::vector<double>& state) override;

  std::size_t num_quadrature_points() const { return weight_.size(); }
  bool fbar_hex8() const { return fbar_hex8_; }
  // Per quadrature point, at the last add(): Cauchy stress (Voigt xx yy zz xy yz zx):
  // sigma = P F^T / J for finite-strain laws, the law's own sigma for small-strain laws
  // (MaterialLaw::small_strain()), and the equivalent plastic strain of the trial history.
  const MatrixX6& cauchy_stress() const { return cauchy_; }
  const Eigen::VectorXd& equivalent_plastic_strain() const { return eqps_; }
  // Elements' first quadrature point index (num_elements + 1 entries).
  const std::vector<std::size_t>& element_qp_offsets() const { return qp_offset_; }
  // Wall seconds of the last add(): the element loop (kinematics and the laws, on the OpenMP
  // threads) and the assembly of the element vectors into f (and K). For bench/fem.
  struct PhaseSeconds {
    double elements = 0.0;
    double assembly = 0.0;
  };
  const PhaseSeconds& last_add_seconds() const { return phase_seconds_; }

  // --- rupture (the model's FailureCriterion per region) and energies per element ---
  // With a criterion in some region the committed state holds, after the points' histories and
  // the EAS alphas, each element's failure time (-1: intact) and the eroded energy, so that
  // restarts keep them. update_failures() (after a commit) marks the elements whose committed
  // mean equivalent plastic strain reached their eps_f as failed at `time` and returns them;
  // an element of a region with erosion then leaves the operator (no force, tangent or energy
  // from the next add() on) and its strain energy and plastic work pass to eroded_energy().
  bool has_failure_criteria() const { return failure_offset_ != kNoFailure; }
  bool erosion() const { return erosion_; }
  std::vector<std::size_t> update_failures(double time);
  double failure_time(std::size_t e) const;  // -1 while intact
  bool failed(std::size_t e) const { return failure_time(e) >= 0.0; }
  bool eroded(std::size_t e) const { return element_erodes_[e] != 0 && failed(e); }
  double failure_strain(std::size_t e) const { return element_failure_strain_[e]; }
  // RTCL and BWH (FailureCriterion::uses_damage()): the committed mean damage of element e's
  // points, accumulated by update_failures() (before its check) from the stress of the last
  // add() and the step's plastic strain increments, held in the committed state after the
  // failure times; the element fails at 1. -1 for elements without such a criterion.
  double element_damage(std::size_t e) const;
  std::size_t num_failed() const;
  // strain energy and plastic work of the eroded elements at erosion, plus what the solver adds
  // (the kinetic energy of their mass) [J]
  double eroded_energy() const;
  void add_eroded_energy(double w);
  // committed mean equivalent plastic strain of element e
  double element_plastic_strain(std::size_t e) const;
  // int W dV of each element at the last add() (0 for eroded elements)
  const std::vector<double>& element_strain_energy() const { return element_energy_; }
  // committed plastic work of element e [J]
  double element_plastic_work(std::size_t e) const;

  // The reduced Hex8's enhanced thickness strain beta, updated once per explicit step
  // (beta_k+1 = beta_k - h_k+1 / K_bb, h = d W / d beta at (u_k+1, beta_k)): between two
  // evaluations the laws see F change by beta's increment too, whose work the nodal forces do
  // not do. Over the step from F_k = F(u_k, beta_k-1) to F_k+1 = F(u_k+1, beta_k) the laws receive
  // the nodal forces' trapezoidal work plus 1/2 (h_k + h_k+1)(beta_k - beta_k-1) =
  // -1/2 (h_k + h_k+1) h_k / K_bb: the lagged update relaxes the mode and dissipates
  //   W_beta = sum_steps 1/2 (h_k + h_k+1) h_k / K_bb  (about h^2 / K_bb a step, >= 0)
  // (committed, in the state: h_k per element and the sum) [J]; 0 without reduced Hex8.
  double enhanced_strain_work() const {
    return enhanced_work_offset_ == kNoFailure ? 0.0 : committed_[enhanced_work_offset_];
  }

 private:
  using ElementDisplacements = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxElementNodes, 3>;
  // One element's fe and, when ke != nullptr, ke (zeroed by the caller); adds its strain energy
  // to `energy`, writes the points' stresses and trial history (its own points only: elements
  // may be evaluated concurrently). Plain: the element's own rule; F-bar: Hex8.
  // `fabs` (one entry per node) gets the element's round-off bound of its nodal forces.
  void evaluate_plain(std::size_t e, const ElementDisplacements& ue, ElementVector& fe,
                      ElementMatrix* ke, double& energy, ElementVector& fabs);
  void evaluate_fbar(std::size_t e, const ElementDisplacements& ue, ElementVector& fe,
                     ElementMatrix* ke, double& energy, ElementVector& fabs);
  void evaluate_eas(std::size_t e, const ElementDisplacements& ue, ElementVector& fe,
                    ElementMatrix* ke, double& energy, ElementVector& fabs);
  // the reduced Hex8 (force only: central difference)
  void evaluate_reduced(std::size_t e, const ElementDisplacements& ue, ElementVector& fe,
                        ElementMatrix* ke, double& energy, ElementVector& fabs);
  // appends an element's hourglass vectors and stiffnesses, its enhanced mode to reduced_data_ (after its points' weights)
  void setup_reduced_hex8(const ElementCoordinates& x, int thickness_axis,
                          const Mat3& j0_inv, const Vec3& elastic);
  // Throws Error naming element e and where it is when det F <= 0 at one of its points.
  void require_not_inverted(std::size_t e, double det_f) const;
  // Element e's fe, fabs and energy, and ke when not null (each zeroed first).
  void evaluate_element(std::size_t e, const Eigen::VectorXd& u, ElementVector& fe,
                        ElementMatrix* ke, ElementVector& fabs, double& energy);
  // add() without a tangent (explicit steps): elements, then nodes, in parallel.
  void add_force_only(const Eigen::VectorXd& u, Eigen::VectorXd& f_int);
  // add_force_only()'s buffers: element e's nodal values from flat_offset_[e] (fe: 3 each);
  // per node n, node_incidence_[node_incidence_offset_[n] ...] its flat indices in element order
  std::vector<std::size_t> flat_offset_, node_incidence_offset_, node_incidence_;
  std::vector<double> flat_fe_, flat_fabs_;
  // Per-element results of one chunk of elements (add() computes a chunk in parallel and adds
  // it to f and K in element order): sized once, reused.
  std::vector<ElementVector> chunk_fe_;
  std::vector<ElementMatrix> chunk_ke_;
  std::vector<double> chunk_energy_;
  std::vector<ElementVector> chunk_fabs_;
  Eigen::VectorXd node_round_off_;  // per node: sum of the elements' round-off bounds
  const Mesh& mesh_;
  bool fbar_hex8_ = false;
  std::vector<std::shared_ptr<const MaterialLaw>> region_laws_;
  std::vector<const MaterialLaw*> element_law_;
  std::vector<double> element_modulus_;          // per element: its law's largest |A| entry at rest
  std::vector<std::size_t> qp_offset_;           // per element
  std::vector<std::size_t> state_offset_;        // per quadrature point (+1)
  std::vector<double> gradients_;                // per qp: n x 3 dN/dX, row-major
  std::vector<std::size_t> gradient_offset_;     // per qp: start in gradients_
  std::vector<double> gradient_norms_;  // per qp: |dN_a/dX| of its nodes, from gradient_offset_ / 3
  std::vector<double> weight_;                   // per qp: det J w
  bool eas_hex8_ = false;                        // Hex8 elements are EAS
  std::vector<double> eas_gradients_;            // per EAS qp: the 3 x 3 rows g_J, row-major
  std::vector<std::size_t> eas_offset_;          // per element: alpha's start in the state (EAS)
  std::vector<std::size_t> eas_gradient_start_;  // per element: its first g_J in eas_gradients_
  std::vector<double> eas_norms_;                // per EAS qp: |G| (11 x 3) and |g_J| (3 x 3)
  // reduced Hex8 (Hex8Formulation::Reduced): per element from reduced_start_[e]
  // (kReducedData doubles): gamma_1, gamma_4 (8 each), K_1, K_4 (3 x 3, row-major), c (the
  // thickness coordinate's gradient at the centre), n = c / |c|, the transverse-shear rows
  // c_eta, c_xi (8 x 3 each, row-major), mu V / 3, 1 / K_beta_beta; per point (j0 / j) zeta;
  // its beta at eas_offset_[e] in the state
  static constexpr std::size_t kReducedData = 8 + 8 + 9 + 9 + 3 + 3 + 24 + 24 + 1 + 1;
  bool reduced_hex8_ = false;
  std::vector<double> reduced_data_;
  std::vector<std::size_t> reduced_start_;
  std::vector<double> reduced_point_scale_;
  std::vector<double> committed_, trial_;
  double energy_ = 0.0;
  double round_off_ = 0.0;
  // rupture: see update_failures()
  static constexpr std::size_t kNoFailure = static_cast<std::size_t>(-1);
  std::size_t failure_offset_ = kNoFailure;      // failure times' start in the state
  bool erosion_ = false;                         // some region erodes
  std::vector<double> element_failure_strain_;   // per element: eps_f (inf: none)
  std::vector<char> element_erodes_;             // per element: its region erodes
  // RTCL and BWH: per point (damage, eps_p at its last update) from damage_offset_ in the state
  std::size_t damage_offset_ = kNoFailure;
  std::vector<std::unique_ptr<FailureCriterion>> region_damage_criteria_;
  std::vector<const FailureCriterion*> element_damage_criterion_;  // per element (null: none)
  std::vector<Vec3> element_normal_;  // per element: its plate's normal (BWH)
  void update_damage();
  std::vector<double> element_energy_;           // per element: int W dV at the last add()
  // reduced Hex8: per element the enhanced strain's work of the last add() (enhanced_strain_work),
  // summed at commit into the state's slot enhanced_work_offset_ (kNoFailure: none)
  std::vector<double> enhanced_work_trial_;
  std::size_t enhanced_work_offset_ = kNoFailure;
  MatrixX6 cauchy_;
  Eigen::VectorXd eqps_;
  PhaseSeconds phase_seconds_;
  // what the laws are told of the step (set_time, set_dynamic); the committed and trial times
  MaterialStep step_;
  double committed_time_ = 0.0, trial_time_ = 0.0;
};

}  // namespace partita::fem
