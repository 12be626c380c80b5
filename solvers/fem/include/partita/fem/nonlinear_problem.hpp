#pragma once
#include "partita/fem/types.hpp"

namespace partita::fem {

// A system of equations R(x) = 0 for the Newton solver (x: the free dofs).
class NonlinearProblem {
 public:
  virtual ~NonlinearProblem() = default;
  // r = R(x) (out-of-balance force); when k != nullptr also the tangent K = -dR/dx. May throw
  // Error where x is inadmissible (an inverted element): Newton treats that as a failed trial.
  virtual void residual(const Eigen::VectorXd& x, Eigen::VectorXd& r, SparseMatrix* k) = 0;
};

}  // namespace partita::fem
