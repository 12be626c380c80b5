#pragma once
#include <memory>
#include <vector>

#include "partita/fem/linear_solver.hpp"
#include "partita/fem/newton_solver.hpp"
#include "partita/fem/solver_timings.hpp"
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Implicit Newmark, one integrator for both kinds of operator.
//
// Constant tangent (InternalForceOperator::constant_tangent(): f_int = K u, linear elasticity):
// one linear system a step,
//   K_eff u_1 = F_1 + M (c0 u + c2 v + c3 a) + C (c1 u + c4 v + c5 a),
//   K_eff = K + gamma/(beta dt) C + 1/(beta dt^2) M,   C = alpha M + beta_R K,
// K_eff factorised on the first step and whenever dt changes (a step within a relative 1e-9 of
// the factorised one reuses it: a coupling hands over substeps as differences of absolute times),
// each step one right-hand side and one pair of triangular solves; then
//   a_1 = c0 (u_1 - u) - c2 v - c3 a,   v_1 = v + h ((1 - gamma) a + gamma a_1).
//
// Otherwise Newton on the displacement u_1 at t + dt:
//   a_1 = (u_1 - u - dt v) / (beta dt^2) - (1/(2 beta) - 1) a,
//   v_1 = v + dt ((1 - gamma) a + gamma a_1),
//   R(u_1) = F_1 - f_int(u_1) - M a_1 - C v_1 = 0 (free dofs), C = alpha M + beta_R K0,
//   tangent K_t + (1/(beta dt^2) + alpha gamma/(beta dt)) M + beta_R gamma/(beta dt) K0.
// A step whose Newton fails is split in two halves, recursively (max_cutbacks levels); after
// that it throws Error with the time, the step size and the residual. The history is committed
// after each accepted (sub)step. Needs a valid acceleration at the start.
class NewmarkIntegrator {
 public:
  NewmarkIntegrator(double beta, double gamma, NewtonOptions options = {},
                    LinearSolver linear_solver = LinearSolver::Automatic,
                    FillOrdering ordering = FillOrdering::Automatic,
                    FactorThreading factor_threading = FactorThreading::Automatic);
  void step(StructuralSystem& system, Kinematics& kin, double dt);
  // Constant tangent: factorise K_eff for the step size dt now (a restored state's step size,
  // so that its steps are those of the run that saved it, bit for bit). The solve threading of
  // that factor and where its factorisations are counted (optional) are set before.
  void factorise(StructuralSystem& system, double dt);
  void set_solve_threading(SolveThreading threading) { solve_threading_ = threading; }
  void set_timings(SolverTimings* timings) { timings_ = timings; }
  // The step size K_eff was factorised for (-1: none yet).
  double factor_dt() const { return factor_dt_; }
  const NewtonReport& last_report() const { return last_; }
  // Newton iterations and cut-backs as text (see ProgressCallback).
  void set_progress(ProgressCallback progress) {
    progress_ = progress;
    newton_.set_progress(std::move(progress));
  }
  // Newton iterations of the last step(), summed over its cut-back substeps and failed tries.
  int step_iterations() const { return step_iterations_; }

 private:
  void step_constant_tangent(StructuralSystem& system, Kinematics& kin, const SparseMatrix& k,
                             double dt);
  bool try_step(StructuralSystem& system, Kinematics& kin, double dt);
  void step_with_cutback(StructuralSystem& system, Kinematics& kin, double dt, int depth);
  double beta_, gamma_;
  NewtonSolver newton_;
  // constant tangent: K_eff's factor for factor_dt_, K_eff's free-constrained block, and the
  // partitioned K and M it is made of (split once)
  LinearSolver linear_solver_;
  FillOrdering ordering_;
  FactorThreading factor_threading_;
  SolveThreading solve_threading_ = SolveThreading::Automatic;
  std::unique_ptr<SparseFactorisation> factor_;
  double factor_dt_ = -1.0;
  SparseMatrix k_ff_, k_fc_, m_ff_, m_fc_, keff_fc_;
  SolverTimings* timings_ = nullptr;
  ProgressCallback progress_;

 public:
  // Work storage of a step, kept between steps (sized once, then reused: no allocation per step
  // once the patterns are set). Public only so that the step's problem can use it.
  struct Work {
    Eigen::VectorXd f1, u1, x, f_int, v1, a1, v_mid, m_v;  // the step
    Eigen::VectorXd rhs;                                   // a residual evaluation
    Eigen::VectorXd pm, pc, uc, rf, uf;                    // a constant-tangent step
    SparseMatrix k_full, k_fc;                             // the tangent on all dofs, K_fc
    bool mass_pattern_checked = false, mass_pattern_same = false;
    bool k0_pattern_checked = false, k0_pattern_same = false;
    bool k_full_foreign = false;  // k_full's pattern is a sum's, not the operator's
    double mass_row_max = -1.0;   // largest absolute row sum of M (< 0: not computed yet)
  };

 private:
  Work work_;
  NewtonReport last_;
  int step_iterations_ = 0;
};

}  // namespace partita::fem
