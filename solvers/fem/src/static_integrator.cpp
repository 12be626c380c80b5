#include "partita/fem/static_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// R(u_f) = F_f - f_int(u)_f with u_c held; K = (K_t)_ff.
class StaticProblem final : public NonlinearProblem {
 public:
  StaticProblem(StructuralSystem& s, const Eigen::VectorXd& f, Eigen::VectorXd& u)
      : s_(s), f_(f), u_(u) {}
  void residual(const Eigen::VectorXd& x, Eigen::VectorXd& r, SparseMatrix* k) override {
    s_.dofs().scatter_free(x, u_);
    s_.internal_forces().evaluate(u_, f_int_, k != nullptr ? &k_full_ : nullptr);
    s_.dofs().gather_free(f_ - f_int_, r);
    if (k != nullptr) s_.dofs().split(k_full_, *k, k_fc_);
    // F_ref = max(|F|, |f_int|) over all dofs (f_int holds the reactions on the constrained
    // ones); r_eps = the operator's round-off bound + eps |F|
    const double nf = f_.norm(), ni = f_int_.norm();
    scales_.force = std::max(nf, ni);
    scales_.round_off =
        s_.internal_forces().round_off() + std::numeric_limits<double>::epsilon() * nf;
  }
  ResidualScales scales() const override { return scales_; }

 private:
  StructuralSystem& s_;
  const Eigen::VectorXd& f_;
  Eigen::VectorXd& u_;
  Eigen::VectorXd f_int_;
  SparseMatrix k_full_, k_fc_;
  ResidualScales scales_;
};

}  // namespace

std::string StaticIntegrator::failure_message(const NewtonReport& rep, int step, double lambda,
                                              double next, double t1, double stiffness_first,
                                              double stiffness_last) const {
  const NewtonOptions& o = newton_.options();
  std::ostringstream msg;
  // A limit load: the load factor had grown (converged increments), then no equilibrium was
  // found beyond it with the increment halved max_cutbacks times, and Newton failed the way a
  // limit point makes it fail: the tangent singular (no stiffness left), |R| stagnating or
  // growing, trial points the material law rejects (return mappings far beyond the yield
  // surface); or still converging too slowly after the secant stiffness d lambda / |du| of the
  // converged increments had fallen below a fifth of the first's. Not for a stall at round-off
  // or an inverted element (numerical or geometric trouble, not the load).
  const double ratio = stiffness_first > 0.0 ? stiffness_last / stiffness_first : 1.0;
  const bool limit_failure = rep.failure_kind == NewtonFailure::SingularTangent ||
                             rep.failure_kind == NewtonFailure::Stagnation ||
                             rep.failure_kind == NewtonFailure::Divergence ||
                             rep.failure_kind == NewtonFailure::InadmissibleTrial ||
                             (rep.failure_kind == NewtonFailure::SlowConvergence && ratio < 0.2);
  if (lambda > 0.0 && limit_failure) {
    msg << "limit load: the load factor no longer grows; the largest load factor reached is "
        << lambda << " (0: the state at the start of the step, 1: the loads at t = " << t1
        << "); the secant stiffness of the last converged increment was " << 100.0 * ratio
        << " % of the first's, and no equilibrium was found beyond it in " << o.max_cutbacks
        << " halvings of the increment (" << rep.failure
        << "). The loads exceed what the structure can carry (a collapse, e.g. a plastic "
           "mechanism): keep them below about "
        << lambda << " times the applied ones, or prescribe a displacement instead";
    return msg.str();
  }
  msg << "static Newton solver failed at load step " << step << " (load factor " << lambda << " -> "
      << next << " of the step to t = " << t1 << ") after " << o.max_cutbacks
      << " cut-backs: " << rep.failure
      << "; last residual |R| = " << (rep.residual_norms.empty() ? 0.0 : rep.residual_norms.back())
      << " N (tolerance " << rep.tolerance << " N).";
  switch (rep.failure_kind) {
    case NewtonFailure::RoundOffStall:
      msg << " The residual cannot go lower in double precision: raise force_tolerance or "
             "round_off_factor (more load steps do not help)";
      break;
    case NewtonFailure::InvertedElement:
    case NewtonFailure::InadmissibleStart:
      msg << " Elements turn inside out: refine the mesh there, use more load steps, or check "
             "the loads and supports";
      break;
    case NewtonFailure::SingularTangent:
      msg << " Check the supports (a rigid-body motion left free) and the material";
      break;
    default:
      msg << " Use more load steps, a smaller time step, or check the material and supports";
      break;
  }
  return msg.str();
}

StaticIntegrator::~StaticIntegrator() = default;

void StaticIntegrator::solve_constant_tangent(StructuralSystem& system, Kinematics& kin,
                                              const SparseMatrix& k, double t1) {
  const DofPartition& dofs = system.dofs();
  if (factored_ != &k) {
    // K_ff factorised once for this tangent (symbolic analysis and numeric factorisation)
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    dofs.split(k, k_ff_, k_fc_);
    factor_ = std::make_unique<SparseFactorisation>(linear_solver_, ordering_);
    factor_->set_solve_threading(solve_threading_);
    factor_->set_factor_threading(factor_threading_);
    factor_->analyze(k_ff_);
    factorize_or_throw(*factor_, k_ff_, "static stiffness matrix K_ff");
    factored_ = &k;
    if (timings_ != nullptr) {
      timings_->factor_nonzeros = factor_->factor_nonzeros();
      ++timings_->factorisations;
      timings_->factorisation += std::chrono::duration<double>(Clock::now() - t0).count();
    }
  }
  system.external_force(t1, kin.f);
  Eigen::VectorXd uc;
  system.prescribed_values(t1, uc);
  // K_ff u_f = F_f - K_fc u_c
  Eigen::VectorXd rhs(static_cast<Eigen::Index>(dofs.free_dofs().size()));
  for (std::size_t i = 0; i < dofs.free_dofs().size(); ++i)
    rhs[static_cast<Eigen::Index>(i)] = kin.f[dofs.free_dofs()[i]];
  if (uc.size() > 0 && uc.cwiseAbs().maxCoeff() > 0.0) rhs -= k_fc_ * uc;
  Eigen::VectorXd uf;
  factor_->solve(rhs, uf);
  for (std::size_t i = 0; i < dofs.free_dofs().size(); ++i)
    kin.u[dofs.free_dofs()[i]] = uf[static_cast<Eigen::Index>(i)];
  for (std::size_t i = 0; i < dofs.constrained_dofs().size(); ++i)
    kin.u[dofs.constrained_dofs()[i]] = uc[static_cast<Eigen::Index>(i)];
  kin.time = t1;
  kin.v.setZero();
  kin.a.setZero();
}

void StaticIntegrator::solve(StructuralSystem& system, Kinematics& kin, double t1) {
  reports_.clear();
  if (const SparseMatrix* k = system.internal_forces().constant_tangent()) {
    solve_constant_tangent(system, kin, *k, t1);
    return;
  }
  const DofPartition& dofs = system.dofs();
  const Eigen::VectorXd u0 = kin.u;
  Eigen::VectorXd f1, u_target = kin.u;
  system.external_force(t1, f1);
  system.apply_prescribed(t1, u_target);
  // The ramp starts from the load the current state is in equilibrium with: f_int(u_0) on the
  // free dofs (so lambda = 0 is exact even for a state that is not an equilibrium of F_0),
  // the applied F_0 on the constrained ones.
  Eigen::VectorXd f0 = kin.f;
  double internal_scale = 0.0;  // |f_int(u_0)| over all dofs: the loads and the reactions
  {
    Eigen::VectorXd f_int;
    system.internal_forces().set_time(t1, 0.0);
    system.internal_forces().evaluate(u0, f_int, nullptr);
    for (auto d : dofs.free_dofs()) f0[d] = f_int[d];
    internal_scale = f_int.norm();
  }
  const int steps = std::max(1, newton_.options().load_steps);
  double lambda = 0.0, increment = 1.0 / steps;
  const double min_increment = std::ldexp(increment, -newton_.options().max_cutbacks);
  int cutbacks = 0, step = 1;
  // secant stiffness of the converged increments, d lambda / |du|: the first one and the
  // last one (their ratio tells a limit load from a numerical difficulty)
  double stiffness_first = -1.0, stiffness_last = -1.0;
  // The runaway test's stiffness, |dF| / |du| of an increment with dF the change of the loads
  // on the free dofs, against that of the first increment of the first solve under loads (the
  // structure at rest: a load ramped over many solves is measured against it too); none where
  // the loads do not change (a prescribed displacement drives it: nothing can run away).
  Eigen::VectorXd load_change;
  dofs.gather_free(f1 - f0, load_change);
  const double load_norm = load_change.norm();
  double carried = 0.0;  // the last load factor reached with kRunawayStiffness of the reference
  Eigen::VectorXd f_lambda, u_trial, x;
  while (lambda < 1.0) {
    double next = lambda + increment;
    if (next > 1.0 - 1e-12) next = 1.0;
    // F(lambda) = F_0 + lambda (F(t1) - F_0);  u_c(lambda) likewise
    f_lambda = f0 + next * (f1 - f0);
    u_trial = kin.u;
    for (auto d : dofs.constrained_dofs()) u_trial[d] = u0[d] + next * (u_target[d] - u0[d]);
    dofs.gather_free(u_trial, x);
    // a rigid indenter ramps with the loads, from its committed position to that of t1
    system.internal_forces().set_time(t1, next);
    StaticProblem problem(system, f_lambda, u_trial);
    // a lower bound of the force scale: the internal forces of the start (reactions included)
    NewtonReport rep = newton_.solve(problem, x, internal_scale);
    reports_.push_back(rep);
    if (rep.converged) {
      dofs.scatter_free(x, u_trial);
      // evaluate once more at the accepted u so that the trial history belongs to it
      Eigen::VectorXd f_int;
      system.internal_forces().evaluate(u_trial, f_int, nullptr);
      system.internal_forces().commit();
      const double du = (u_trial - kin.u).norm();
      if (du > 0.0) {
        stiffness_last = (next - lambda) / du;
        if (stiffness_first < 0.0) stiffness_first = stiffness_last;
      }
      double ratio = 1.0;
      if (du > 0.0 && load_norm > 0.0) {
        const double stiffness = (next - lambda) * load_norm / du;
        if (!(reference_stiffness_ > 0.0)) reference_stiffness_ = stiffness;
        ratio = stiffness / reference_stiffness_;
      }
      if (ratio >= kRunawayStiffness) carried = next;
      if (model_size_ > 0.0 && ratio < kRunawayStiffness) {
        double moved = 0.0;  // the largest nodal displacement
        for (Eigen::Index i = 0; i + 2 < u_trial.size(); i += 3)
          moved = std::max(moved, u_trial.segment<3>(i).norm());
        if (moved > model_size_) {
          std::ostringstream msg;
          msg << "limit load: the displacement runs away; the largest load factor carried is "
              << carried << " (0: the state at the start of the step, 1: the loads at t = " << t1
              << "). Newton accepted load factor " << next << " with a node moved " << moved
              << " m, more than the model's size (" << model_size_
              << " m), in an increment whose secant stiffness was " << 100.0 * ratio
              << " % of the structure's at rest. The loads exceed what the structure can carry (a "
                 "collapse, e.g. a plastic mechanism): ";
          if (carried > 0.0)
            msg << "keep them below about " << carried << " times the applied ones";
          else
            msg << "keep them at those the step started from";
          msg << ", prescribe a displacement instead, or give the material the hardening it has";
          throw Error(msg.str());
        }
      }
      kin.external_work += 0.5 * (kin.f + f_lambda).dot(u_trial - kin.u);
      kin.u = u_trial;
      kin.f = f_lambda;
      if (progress_) {
        std::ostringstream line;
        line << "load step " << step << ": load factor " << next << " converged in "
             << rep.iterations << " Newton iterations";
        progress_(line.str());
      }
      lambda = next;
      cutbacks = 0;
      ++step;
      continue;
    }
    // the increment is halved down to 1/2^max_cutbacks of the initial one (a count of halvings
    // in a row would let the load factor creep towards a limit point for ever)
    if (++cutbacks > newton_.options().max_cutbacks || increment <= min_increment * (1.0 + 1e-12)) {
      throw Error(failure_message(rep, step, lambda, next, t1, stiffness_first, stiffness_last));
    }
    if (progress_) {
      std::ostringstream line;
      line << "load step " << step << ": load factor " << lambda << " -> " << next << " failed ("
           << rep.failure << "); cut-back " << cutbacks << " of " << newton_.options().max_cutbacks
           << ", increment " << 0.5 * increment;
      progress_(line.str());
    }
    increment *= 0.5;
  }
  kin.time = t1;
  kin.v.setZero();
  kin.a.setZero();
}

}  // namespace partita::fem
