#include "partita/fem/newton_solver.hpp"

#include <cmath>
#include <sstream>

#include "partita/fem/error.hpp"

namespace partita::fem {

NewtonReport NewtonSolver::solve(NonlinearProblem& problem, Eigen::VectorXd& x,
                                 double reference_force) {
  NewtonReport rep;
  Eigen::VectorXd &r = r_, &r_trial = r_trial_, &dx = dx_, &x_trial = x_trial_;
  SparseMatrix& k = k_;
  try {
    problem.residual(x, r, &k);
  } catch (const Error& e) {
    rep.failure = std::string("the start is inadmissible: ") + e.what();
    return rep;
  }
  double r_norm = r.norm();
  rep.residual_norms.push_back(r_norm);
  rep.reference_force = std::max(reference_force, r_norm);
  const double force_tol = options_.force_tolerance * rep.reference_force;
  double energy_0 = -1.0;
  bool k_current = true;  // k is the tangent at x (trial points are evaluated without it)
  for (int it = 0;; ++it) {
    if (!std::isfinite(r_norm)) {
      rep.failure = "the residual is not finite";
      return rep;
    }
    const bool energy_ok =
        it == 0 || rep.energy_norms.back() <= options_.energy_tolerance * energy_0;
    if (r_norm <= force_tol && energy_ok) {
      rep.converged = true;
      rep.iterations = it;
      return rep;
    }
    if (!k_current) {
      // the tangent at the accepted point, only when another iteration needs it (the residual
      // is the same; the last, converged evaluation skips the tangent)
      problem.residual(x, r, &k);
      k_current = true;
    }
    if (it == options_.max_iterations) {
      std::ostringstream msg;
      msg << "no convergence in " << it << " iterations (|R| = " << r_norm << ", tolerance "
          << force_tol << ")";
      rep.failure = msg.str();
      rep.iterations = it;
      return rep;
    }
    // K dx = R
    // symbolic analysis once per sparsity pattern, numeric factorisation per iteration
    if (!factor_) {
      factor_ = std::make_unique<SparseFactorisation>(
          linear_solver_, ordering_, SparseFactorisation::Matrix::SymmetricIndefiniteAllowed);
      factor_->set_factor_threading(factor_threading_);
    }
    if (k.nonZeros() != pattern_nonzeros_ || k.rows() != pattern_size_) {
      factor_->analyze(k);
      pattern_nonzeros_ = k.nonZeros();
      pattern_size_ = k.rows();
    }
    if (!factor_->factorize(k)) {
      rep.failure = "the tangent matrix could not be factorised (singular)";
      rep.iterations = it;
      return rep;
    }
    factor_->solve(r, dx);
    // energy norm |dx . R|
    const double energy = std::abs(dx.dot(r));
    if (energy_0 < 0.0) energy_0 = energy;
    // backtracking line search: accept s where |R(x + s dx)| decreases or (energy line search,
    // see NewtonOptions) where the energy slope along dx, g(s) = dx . R(x + s dx), has fallen
    // to 0.8 |g(0)|
    double s = 1.0;
    bool accepted = false;
    for (int ls = 0; ls <= options_.max_line_search_steps; ++ls, s *= 0.5) {
      x_trial.noalias() = x + s * dx;
      try {
        problem.residual(x_trial, r_trial, nullptr);
      } catch (const Error&) {
        continue;  // inadmissible trial (inverted element): shorter step
      }
      const double n_trial = r_trial.norm();
      if (!std::isfinite(n_trial)) continue;
      // accept a decrease, or the full step when |R| is already at round-off level
      if (n_trial <= (1.0 - 1e-4 * s) * r_norm ||
          (options_.energy_line_search && std::abs(dx.dot(r_trial)) <= 0.8 * energy) ||
          ls == options_.max_line_search_steps || (s == 1.0 && n_trial <= force_tol)) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      rep.failure = "the line search found no admissible step (elements invert)";
      rep.iterations = it;
      return rep;
    }
    x.swap(x_trial);
    r.swap(r_trial);
    k_current = false;
    r_norm = r.norm();
    rep.residual_norms.push_back(r_norm);
    rep.energy_norms.push_back(s * energy);
    rep.step_lengths.push_back(s);
  }
}

}  // namespace partita::fem
