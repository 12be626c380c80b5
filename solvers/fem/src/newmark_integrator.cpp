#include "partita/fem/newmark_integrator.hpp"

#include <sstream>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// R(u_1) = F_1 - f_int(u_1) - M (a_1 + alpha v_1) - beta_R K0 v_1 on the free dofs, with
// a_1 = c0 (u_1 - u) - c2 v - c3 a and v_1 = v + dt ((1 - gamma) a + gamma a_1).
class NewmarkProblem final : public NonlinearProblem {
 public:
  NewmarkProblem(StructuralSystem& s, const Kinematics& kin, const Eigen::VectorXd& f1,
                 Eigen::VectorXd& u1, double beta, double gamma, double dt)
      : s_(s), kin_(kin), f1_(f1), u1_(u1), gamma_(gamma), dt_(dt) {
    c0_ = 1.0 / (beta * dt * dt);
    c2_ = 1.0 / (beta * dt);
    c3_ = 0.5 / beta - 1.0;
  }
  void velocity_acceleration(Eigen::VectorXd& v1, Eigen::VectorXd& a1) const {
    a1 = c0_ * (u1_ - kin_.u) - c2_ * kin_.v - c3_ * kin_.a;
    v1 = kin_.v + dt_ * ((1.0 - gamma_) * kin_.a + gamma_ * a1);
  }
  void residual(const Eigen::VectorXd& x, Eigen::VectorXd& r, SparseMatrix* k) override {
    s_.dofs().scatter_free(x, u1_);
    s_.internal_forces().evaluate(u1_, f_int_, k != nullptr ? &k_full_ : nullptr);
    velocity_acceleration(v1_, a1_);
    const double alpha = s_.mass_damping(), beta_r = s_.stiffness_damping();
    const SparseMatrix& m = s_.mass();
    if (beta_r == 0.0) {
      s_.dofs().gather_free(f1_ - f_int_ - m * (a1_ + alpha * v1_), r);
    } else {
      s_.dofs().gather_free(
          f1_ - f_int_ - m * (a1_ + alpha * v1_) - beta_r * (s_.damping_stiffness() * v1_), r);
    }
    if (k == nullptr) return;
    // K = K_t + (c0 + alpha gamma c2) M + beta_R gamma c2 K0   (d v_1 / d u_1 = gamma c2)
    k_full_ += (c0_ + alpha * gamma_ * c2_) * m;
    if (beta_r != 0.0) k_full_ += (beta_r * gamma_ * c2_) * s_.damping_stiffness();
    s_.dofs().split(k_full_, *k, k_fc_);
  }

 private:
  StructuralSystem& s_;
  const Kinematics& kin_;
  const Eigen::VectorXd& f1_;
  Eigen::VectorXd& u1_;
  double gamma_, dt_, c0_ = 0, c2_ = 0, c3_ = 0;
  Eigen::VectorXd f_int_, v1_, a1_;
  SparseMatrix k_full_, k_fc_;
};

}  // namespace

NewmarkIntegrator::NewmarkIntegrator(double beta, double gamma, NewtonOptions options,
                                     LinearSolver linear_solver, FillOrdering ordering)
    : beta_(beta), gamma_(gamma), newton_(options, linear_solver, ordering) {}

bool NewmarkIntegrator::try_step(StructuralSystem& system, Kinematics& kin, double dt) {
  const double t1 = kin.time + dt;
  Eigen::VectorXd f1, u1 = kin.u, x;
  system.external_force(t1, f1);
  system.apply_prescribed(t1, u1);
  system.dofs().gather_free(u1, x);
  NewmarkProblem problem(system, kin, f1, u1, beta_, gamma_, dt);
  last_ = newton_.solve(problem, x, std::max(f1.norm(), 1e-300));
  step_iterations_ += last_.iterations;
  if (!last_.converged) return false;
  system.dofs().scatter_free(x, u1);
  Eigen::VectorXd f_int, v1, a1;
  system.internal_forces().evaluate(u1, f_int, nullptr);
  system.internal_forces().commit();
  problem.velocity_acceleration(v1, a1);
  // prescribed dofs: Newmark velocity and acceleration of the prescribed motion
  const Eigen::VectorXd v_mid = 0.5 * (kin.v + v1);
  // dt v_mid . C v_mid: exact for average acceleration (the mean of the equations at n and
  // n+1 times u_1 - u = dt v_mid)
  kin.damping_work += dt * system.mass_damping() * v_mid.dot(system.mass() * v_mid);
  if (system.stiffness_damping() != 0.0)
    kin.damping_work +=
        dt * system.stiffness_damping() * v_mid.dot(system.damping_stiffness() * v_mid);
  kin.external_work += 0.5 * (kin.f + f1).dot(u1 - kin.u);
  kin.u = u1;
  kin.v = v1;
  kin.a = a1;
  kin.f = f1;
  kin.time = t1;
  return true;
}

void NewmarkIntegrator::step_with_cutback(StructuralSystem& system, Kinematics& kin, double dt,
                                          int depth) {
  if (try_step(system, kin, dt)) return;
  if (depth >= newton_.options().max_cutbacks) {
    std::ostringstream msg;
    msg << "Newmark Newton solver failed at t = " << kin.time << " with a step of " << dt
        << " s after " << depth << " cut-backs (halvings): " << last_.failure
        << "; last residual |R| = " << last_.residual_norms.back() << " N (tolerance "
        << newton_.options().force_tolerance * last_.reference_force
        << " N). Use a smaller time step or check the material and supports";
    throw Error(msg.str());
  }
  step_with_cutback(system, kin, 0.5 * dt, depth + 1);
  step_with_cutback(system, kin, 0.5 * dt, depth + 1);
}

void NewmarkIntegrator::step(StructuralSystem& system, Kinematics& kin, double dt) {
  step_iterations_ = 0;
  step_with_cutback(system, kin, dt, 0);
}

}  // namespace partita::fem
