#pragma once
#include "partita/fem/types.hpp"

namespace partita::fem {

// Force scales of a residual evaluation, for a convergence test that does not depend on the
// size of the load (NewtonSolver):
//   force: F_ref, the largest norm over all dofs of the terms of the balance (internal force,
//     reactions included; external force; inertia force);
//   round_off: r_eps, an estimate of the error of R in double precision (the internal force's,
//     InternalForceOperator::round_off(), plus eps times the other terms').
struct ResidualScales {
  double force = 0.0;
  double round_off = 0.0;
};

// A system of equations R(x) = 0 for the Newton solver (x: the free dofs).
class NonlinearProblem {
 public:
  virtual ~NonlinearProblem() = default;
  // r = R(x) (out-of-balance force); when k != nullptr also the tangent K = -dR/dx. May throw
  // Error where x is inadmissible (an inverted element): Newton treats that as a failed trial.
  virtual void residual(const Eigen::VectorXd& x, Eigen::VectorXd& r, SparseMatrix* k) = 0;
  // The scales of the last residual() evaluation.
  virtual ResidualScales scales() const = 0;
};

}  // namespace partita::fem
