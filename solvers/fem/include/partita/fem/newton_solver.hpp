#pragma once
#include <memory>

#include "partita/fem/linear_solver.hpp"
#include "partita/fem/newton_options.hpp"
#include "partita/fem/newton_report.hpp"
#include "partita/fem/nonlinear_problem.hpp"

namespace partita::fem {

// Newton-Raphson with a backtracking line search on |R|:
//   K(x_k) dx = R(x_k),  x_k+1 = x_k + s dx  (s = 1, 1/2, ... while |R| does not decrease),
// converged on the force norm and the energy norm (NewtonOptions). The tangent is factorised
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
  // Solves R(x) = 0 from the given x (changed in place; on failure x holds the last iterate).
  NewtonReport solve(NonlinearProblem& problem, Eigen::VectorXd& x, double reference_force);

 private:
  NewtonOptions options_;
  LinearSolver linear_solver_;
  FillOrdering ordering_;
  FactorThreading factor_threading_;
  std::unique_ptr<SparseFactorisation> factor_;
  Eigen::Index pattern_nonzeros_ = -1, pattern_size_ = -1;
  // Work storage kept between solves (a time integrator calls solve() at every step): sized
  // once, then reused; the tangent keeps its pattern, so the problem can refill its values.
  Eigen::VectorXd r_, r_trial_, dx_, x_trial_;
  SparseMatrix k_;
};

}  // namespace partita::fem
