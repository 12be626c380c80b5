#include "partita/fem/central_difference_integrator.hpp"

#include "partita/fem/error.hpp"

namespace partita::fem {

void CentralDifferenceIntegrator::initialise(StructuralSystem& system, Kinematics& kin) {
  if (!system.lumped_mass()) {
    throw Error("central difference needs a lumped (diagonal) mass: set the mass to lumped");
  }
  m_ = system.mass().diagonal();
  system.external_force(kin.time, kin.f);
  system.internal_forces().set_time(kin.time, 0.0);
  system.internal_forces().evaluate(kin.u, kin.f_int, nullptr);
  // a = M^-1 (F - f_int - beta K0 v) - alpha v on the free dofs
  kin.a.setZero();
  const bool stiffness_damped = system.stiffness_damping() != 0.0;
  if (stiffness_damped) cv_ = system.stiffness_damping() * (system.damping_stiffness() * kin.v);
  for (auto d : system.dofs().free_dofs()) {
    const double fd = stiffness_damped ? cv_[d] : 0.0;
    kin.a[d] = (kin.f[d] - kin.f_int[d] - fd) / m_[d] - system.mass_damping() * kin.v[d];
  }
}

void CentralDifferenceIntegrator::step(StructuralSystem& system, Kinematics& kin, double dt) {
  if (m_.size() != kin.u.size()) m_ = system.mass().diagonal();
  const double alpha = system.mass_damping(), beta = system.stiffness_damping();
  const double t1 = kin.time + dt;
  // v_1/2 = v + dt/2 a;  u_1 = u + dt v_1/2
  v_half_ = kin.v + 0.5 * dt * kin.a;
  u1_ = kin.u + dt * v_half_;
  system.apply_prescribed(t1, u1_);
  system.internal_forces().set_time(t1, 1.0);  // a rigid indenter moves with the step
  system.internal_forces().evaluate(u1_, kin.f_int, nullptr);
  system.internal_forces().commit();
  system.external_force(t1, f1_);
  if (beta == 0.0) {
    // a_1 = (M^-1 (F_1 - f_int) - alpha v_1/2) / (1 + alpha dt / 2);  v_1 = v_1/2 + dt/2 a_1
    for (auto d : system.dofs().free_dofs()) {
      kin.a[d] = ((f1_[d] - kin.f_int[d]) / m_[d] - alpha * v_half_[d]) / (1.0 + 0.5 * alpha * dt);
      kin.v[d] = v_half_[d] + 0.5 * dt * kin.a[d];
    }
  } else {
    // the stiffness-proportional force lagged to v_1/2 (explicit: stable for
    // dt <= (2/omega)(sqrt(1 + xi^2) - xi), xi = beta omega / 2):
    // a_1 = (M^-1 (F_1 - f_int - beta K0 v_1/2) - alpha v_1/2) / (1 + alpha dt / 2)
    cv_.noalias() = system.damping_stiffness() * v_half_;
    cv_ *= beta;
    for (auto d : system.dofs().free_dofs()) {
      kin.a[d] = ((f1_[d] - kin.f_int[d] - cv_[d]) / m_[d] - alpha * v_half_[d]) /
                 (1.0 + 0.5 * alpha * dt);
      kin.v[d] = v_half_[d] + 0.5 * dt * kin.a[d];
    }
    kin.damping_work += dt * v_half_.dot(cv_);
  }
  for (auto d : system.dofs().constrained_dofs()) {
    kin.v[d] = (u1_[d] - kin.u[d]) / dt;
    kin.a[d] = 0.0;
  }
  // damping work dt v_1/2 . alpha M v_1/2 (+ dt v_1/2 . beta K0 v_1/2 above)
  if (alpha != 0.0) kin.damping_work += dt * alpha * v_half_.dot(m_.cwiseProduct(v_half_));
  kin.external_work += 0.5 * (kin.f + f1_).dot(u1_ - kin.u);
  kin.u.swap(u1_);
  kin.f.swap(f1_);
  kin.time = t1;
}

}  // namespace partita::fem
