#pragma once
#include <memory>

#include "partita/fem/linear_solver.hpp"
#include "partita/fem/newton_options.hpp"
#include "partita/fem/newton_report.hpp"
#include "partita/fem/nonlinear_problem.hpp"
#include "partita/fem/progress_callback.hpp"

namespace partita::fem {

// Newton-Raphson with a backtracking line search on |R|:
//   K(x_k) dx = R(x_k),  x_k+1 = x_k + s dx  (s = 1, 1/2, ... while |R| does not decrease),
// converged on the force norm and the energy norm (NewtonOptions):
//   |R_k| <= max(force_tolerance F_ref(x_k), round_off_factor r_eps(x_k)),
//   |dx_k . R_k-1| <= energy_tolerance |dx_1 . R_0|  (or |R_k| <= round_off_factor r_eps).
// The force criterion follows Abaqus (Analysis User's Guide, "Convergence criteria for
// nonlinear problems": the largest residual against the time-averaged force of the model,
// reactions included), not MOOSE's or deal.II step-44's |R_k| / |R_0|: a scale from the forces
// of the balance itself (F_ref, over all dofs, so that the reactions count) is the same whatever
// the size of the load and of its increment, where |R_0| of an increment shrinks with the
// increment and asks for ever more digits. Abaqus's zero-force fallback and its correction
// test are replaced by an absolute floor at the round-off of the residual, r_eps: the internal
// force of a stiff body is a sum of large element contributions evaluated at F = I + grad u,
// rounded to eps |F|, so R cannot be computed more accurately than about eps (|P| + |A| |F|)
// |grad N| dV summed over the elements (InternalForceOperator::round_off()); a test below that
// floor can only stall (steel at E = 210 GPa: |R| stops near 1e-7 N whatever the load). The
// energy criterion beside it (as Abaqus's and step-44's) keeps small loads honest.
// Failures are classified (NewtonFailure): a stall at round-off, stagnation above it,
// divergence, slow convergence, inverted elements, a singular tangent. The tangent is factorised
// by a sparse Cholesky (SparseFactorisation: CHOLMOD or Eigen's LDL^T) whose symbolic analysis
// is kept while the sparsity pattern is unchanged; each iteration refactorises the values.
// Trial points of the line search are evaluated without the tangent; it is computed at the
// accepted point only when another iteration follows (the converged one never needs it).
// Never throws for non-convergence: the report says what happened, the caller cuts back.
class NewtonSolver {
 public:
  explicit NewtonSolver(NewtonOptions options = {},
                        LinearSolver linear_solver = LinearSolver::Automatic,
                        FillOrdering ordering = FillOrdering::Automatic,
                        FactorThreading factor_threading = FactorThreading::Automatic)
      : options_(options),
        linear_solver_(linear_solver),
        ordering_(ordering),
        factor_threading_(factor_threading) {}
  const NewtonOptions& options() const { return options_; }
  // One line per iteration (|R|, tolerance, energy, step length) when set (see
  // ProgressCallback).
  void set_progress(ProgressCallback progress) { progress_ = std::move(progress); }
  // Solves R(x) = 0 from the given x (changed in place; on failure x holds the last iterate).
  // reference_force: a lower bound of F_ref from the caller (e.g. the forces of the state the
  // step starts from), 0 for none.
  NewtonReport solve(NonlinearProblem& problem, Eigen::VectorXd& x, double reference_force);

 private:
  NewtonOptions options_;
  LinearSolver linear_solver_;
  FillOrdering ordering_;
  FactorThreading factor_threading_;
  ProgressCallback progress_;
  std::unique_ptr<SparseFactorisation> factor_;
  Eigen::Index pattern_nonzeros_ = -1, pattern_size_ = -1;
  // Work storage kept between solves (a time integrator calls solve() at every step): sized
  // once, then reused; the tangent keeps its pattern, so the problem can refill its values.
  Eigen::VectorXd r_, r_trial_, dx_, x_trial_;
  SparseMatrix k_;
};

}  // namespace partita::fem
