#pragma once
// Shared helpers of the nonlinear FEM tests (not a test file itself).
#include <Eigen/Dense>
#include <functional>

#include "fem_test_helpers.hpp"
#include "partita/fem/internal_force_operator.hpp"

namespace partita::fem::test {

// Largest relative deviation |K du - (f(u + h du) - f(u - h du)) / 2h| / |K du| over random
// directions du: the tangent against central finite differences of the internal force. Each
// evaluation starts from the committed history, so this checks the algorithmic tangent.
inline double tangent_fd_error(InternalForceOperator& op, const Eigen::VectorXd& u, double h,
                               int directions, unsigned long long seed) {
  Lcg rng(seed);
  Eigen::VectorXd f, fp, fm;
  SparseMatrix k;
  op.evaluate(u, f, &k);
  double worst = 0.0;
  for (int d = 0; d < directions; ++d) {
    Eigen::VectorXd du(u.size());
    for (Eigen::Index i = 0; i < du.size(); ++i) du[i] = rng.next();
    op.evaluate(u + h * du, fp, nullptr);
    op.evaluate(u - h * du, fm, nullptr);
    const Eigen::VectorXd kdu = k * du;
    const Eigen::VectorXd fd = (fp - fm) / (2.0 * h);
    worst = std::max(worst, (kdu - fd).norm() / kdu.norm());
  }
  return worst;
}

// Root of a monotone scalar function on [lo, hi] by bisection to round-off.
inline double bisect(const std::function<double(double)>& g, double lo, double hi) {
  double glo = g(lo);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    const double gm = g(mid);
    if ((gm > 0) == (glo > 0)) {
      lo = mid;
      glo = gm;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

}  // namespace partita::fem::test
