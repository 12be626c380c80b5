#pragma once
#include <vector>

#include "partita/fem/newton_solver.hpp"
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Implicit Newmark for a nonlinear structure, Newton on the displacement u_1 at t + dt:
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
  const NewtonReport& last_report() const { return last_; }
  // Newton iterations and cut-backs as text (see ProgressCallback).
  void set_progress(ProgressCallback progress) {
    progress_ = progress;
    newton_.set_progress(std::move(progress));
  }
  // Newton iterations of the last step(), summed over its cut-back substeps and failed tries.
  int step_iterations() const { return step_iterations_; }

 private:
  bool try_step(StructuralSystem& system, Kinematics& kin, double dt);
  void step_with_cutback(StructuralSystem& system, Kinematics& kin, double dt, int depth);
  double beta_, gamma_;
  NewtonSolver newton_;
  ProgressCallback progress_;

 public:
  // Work storage of a step, kept between steps (sized once, then reused: no allocation per step
  // once the patterns are set). Public only so that the step's problem can use it.
  struct Work {
    Eigen::VectorXd f1, u1, x, f_int, v1, a1, v_mid, m_v;  // the step
    Eigen::VectorXd rhs;                                   // a residual evaluation
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
