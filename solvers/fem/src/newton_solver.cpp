#include "partita/fem/newton_solver.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "partita/fem/error.hpp"
#include "partita/fem/inverted_element_error.hpp"

namespace partita::fem {
namespace {

// Why the iterations ran out: from the residual history (k = 0 the start).
//   divergence: |R| ended above its start;
//   a stall at round-off: |R| <= r_eps (the estimate bounds the error; stalls lie below it)
//     and the last three iterations lowered it by less than a factor 2;
//   stagnation: above round-off, the last three iterations lowered |R| by less than a factor 2,
//     or all of them together by less than a factor 10;
//   otherwise still converging, too slowly.
NewtonFailure classify(const std::vector<double>& r, double round_off) {
  const double last = r.back();
  if (last > r.front()) return NewtonFailure::Divergence;
  const bool stalled = r.size() >= 4 && last > 0.5 * r[r.size() - 4];
  if (stalled && last <= round_off) return NewtonFailure::RoundOffStall;
  if (stalled || last > 0.1 * r.front()) return NewtonFailure::Stagnation;
  return NewtonFailure::SlowConvergence;
}

}  // namespace

NewtonReport NewtonSolver::solve(NonlinearProblem& problem, Eigen::VectorXd& x,
                                 double reference_force) {
  NewtonReport rep;
  Eigen::VectorXd &r = r_, &r_trial = r_trial_, &dx = dx_, &x_trial = x_trial_;
  SparseMatrix& k = k_;
  try {
    problem.residual(x, r, &k);
  } catch (const Error& e) {
    rep.failure = std::string("the start is inadmissible: ") + e.what();
    rep.failure_kind = NewtonFailure::InadmissibleStart;
    return rep;
  }
  double r_norm = r.norm();
  rep.residual_norms.push_back(r_norm);
  // tolerance at the current iterate: max(force_tolerance F_ref, round_off_factor r_eps)
  auto update_tolerance = [&]() {
    const ResidualScales sc = problem.scales();
    rep.reference_force = std::max(reference_force, sc.force);
    rep.round_off = sc.round_off;
    rep.tolerance = std::max(options_.force_tolerance * rep.reference_force,
                             options_.round_off_factor * rep.round_off);
  };
  update_tolerance();
  double energy_0 = -1.0;
  bool k_current = true;     // k is the tangent at x (trial points are evaluated without it)
  std::string inadmissible;  // the last inadmissible trial point's error
  bool inverted = false;     // ... and whether it was an inverted element
  for (int it = 0;; ++it) {
    if (!std::isfinite(r_norm)) {
      rep.failure = "the residual is not finite";
      rep.failure_kind = NewtonFailure::NotFinite;
      return rep;
    }
    const bool at_round_off = r_norm <= options_.round_off_factor * rep.round_off;
    const bool energy_ok =
        it == 0 || at_round_off || rep.energy_norms.back() <= options_.energy_tolerance * energy_0;
    if (progress_) {
      std::ostringstream line;
      line << "Newton " << it << ": |R| = " << r_norm << " N (tolerance " << rep.tolerance
           << " N: " << options_.force_tolerance << " x " << rep.reference_force << ", round-off "
           << rep.round_off << ")";
      if (it > 0)
        line << ", |dx.R| = " << rep.energy_norms.back() << ", step " << rep.step_lengths.back();
      progress_(line.str());
    }
    if (r_norm <= rep.tolerance && energy_ok) {
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
      rep.failure_kind = classify(rep.residual_norms, rep.round_off);
      std::ostringstream msg;
      msg << "no convergence in " << it << " iterations (|R| = " << r_norm << " N, tolerance "
          << rep.tolerance << " N";
      switch (rep.failure_kind) {
        case NewtonFailure::RoundOffStall:
          msg << "): |R| stalled at the round-off level of the internal force (estimated "
              << rep.round_off << " N; F_ref = " << rep.reference_force
              << " N); the tolerance asks for more digits than double precision gives: raise "
                 "force_tolerance or round_off_factor";
          break;
        case NewtonFailure::Stagnation:
          msg << "): |R| stagnates far above round-off (" << rep.round_off
              << " N): a limit point of the load, a step too large, or an inconsistent tangent";
          break;
        case NewtonFailure::Divergence:
          msg << "): diverging, |R| grew from " << rep.residual_norms.front() << " N";
          break;
        default:
          msg << "): still decreasing slowly from " << rep.residual_norms.front() << " N";
          break;
      }
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
      rep.failure =
          "the tangent matrix could not be factorised (singular: a mechanism, or a limit point "
          "of the load where the structure has no stiffness left)";
      rep.failure_kind = NewtonFailure::SingularTangent;
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
      } catch (const InvertedElementError& e) {
        inadmissible = e.what();
        inverted = true;
        continue;  // inadmissible trial: shorter step
      } catch (const Error& e) {
        inadmissible = e.what();
        inverted = false;
        continue;
      }
      const double n_trial = r_trial.norm();
      if (!std::isfinite(n_trial)) continue;
      // accept a decrease, or the full step when |R| is already within the tolerance
      if (n_trial <= (1.0 - 1e-4 * s) * r_norm ||
          (options_.energy_line_search && std::abs(dx.dot(r_trial)) <= 0.8 * energy) ||
          ls == options_.max_line_search_steps || (s == 1.0 && n_trial <= rep.tolerance)) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      rep.failure = "the line search found no admissible step";
      if (!inadmissible.empty()) {
        rep.failure += ": " + inadmissible;
        rep.failure_kind =
            inverted ? NewtonFailure::InvertedElement : NewtonFailure::InadmissibleTrial;
      } else {
        rep.failure_kind = NewtonFailure::NotFinite;
      }
      rep.iterations = it;
      return rep;
    }
    x.swap(x_trial);
    r.swap(r_trial);
    k_current = false;
    r_norm = r.norm();
    update_tolerance();
    rep.residual_norms.push_back(r_norm);
    rep.energy_norms.push_back(s * energy);
    rep.step_lengths.push_back(s);
  }
}

}  // namespace partita::fem
