#include "partita/fem/static_integrator.hpp"

#include <algorithm>
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
  }

 private:
  StructuralSystem& s_;
  const Eigen::VectorXd& f_;
  Eigen::VectorXd& u_;
  Eigen::VectorXd f_int_;
  SparseMatrix k_full_, k_fc_;
};

}  // namespace

void StaticIntegrator::solve(StructuralSystem& system, Kinematics& kin, double t1) {
  reports_.clear();
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
    system.internal_forces().evaluate(u0, f_int, nullptr);
    for (auto d : dofs.free_dofs()) f0[d] = f_int[d];
    internal_scale = f_int.norm();
  }
  const int steps = std::max(1, newton_.options().load_steps);
  double lambda = 0.0, increment = 1.0 / steps;
  int cutbacks = 0, step = 1;
  Eigen::VectorXd f_lambda, u_trial, x;
  while (lambda < 1.0) {
    double next = lambda + increment;
    if (next > 1.0 - 1e-12) next = 1.0;
    // F(lambda) = F_0 + lambda (F(t1) - F_0);  u_c(lambda) likewise
    f_lambda = f0 + next * (f1 - f0);
    u_trial = kin.u;
    for (auto d : dofs.constrained_dofs()) u_trial[d] = u0[d] + next * (u_target[d] - u0[d]);
    dofs.gather_free(u_trial, x);
    StaticProblem problem(system, f_lambda, u_trial);
    // force scale of the convergence test: the applied loads or the internal forces of the
    // start (reactions included), whichever is larger
    const double reference = std::max({f_lambda.norm(), internal_scale, 1e-300});
    NewtonReport rep = newton_.solve(problem, x, reference);
    reports_.push_back(rep);
    if (rep.converged) {
      dofs.scatter_free(x, u_trial);
      // evaluate once more at the accepted u so that the trial history belongs to it
      Eigen::VectorXd f_int;
      system.internal_forces().evaluate(u_trial, f_int, nullptr);
      system.internal_forces().commit();
      kin.external_work += 0.5 * (kin.f + f_lambda).dot(u_trial - kin.u);
      kin.u = u_trial;
      kin.f = f_lambda;
      lambda = next;
      cutbacks = 0;
      ++step;
      continue;
    }
    if (++cutbacks > newton_.options().max_cutbacks) {
      std::ostringstream msg;
      msg << "static Newton solver failed at load step " << step << " (load factor " << lambda
          << " -> " << next << " of the step to t = " << t1 << ") after "
          << newton_.options().max_cutbacks << " cut-backs: " << rep.failure
          << "; last residual |R| = " << rep.residual_norms.back() << " N (tolerance "
          << newton_.options().force_tolerance * rep.reference_force
          << " N). Use more load steps, a smaller time step, or check the material and supports";
      throw Error(msg.str());
    }
    increment *= 0.5;
  }
  kin.time = t1;
  kin.v.setZero();
  kin.a.setZero();
}

}  // namespace partita::fem
