#include "partita/fem/central_difference_integrator.hpp"

#include <algorithm>
#include <limits>

#include "parallel_loop.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// body(i0, i1) over [0, n) in blocks, on the OpenMP threads: for the element-wise updates of a
// step (each entry written by one thread, so the bits do not depend on the thread count; the
// sums, external and damping work, stay serial).
template <class Body>
void for_blocks(std::size_t n, Body body) {
  constexpr std::size_t kBlock = 8192;
  const auto blocks = static_cast<long>((n + kBlock - 1) / kBlock);
  detail::parallel_for_first_error(blocks, 4, [&](long b) {
    const std::size_t i0 = static_cast<std::size_t>(b) * kBlock;
    body(i0, std::min(n, i0 + kBlock));
  });
}

}  // namespace

void CentralDifferenceIntegrator::load_mass(StructuralSystem& system) {
  m_ = system.mass().diagonal();
  // a massless node stays put: a = f / m_max_double ~ 0 (its velocity is zero, see the header)
  for (Eigen::Index d = 0; d < m_.size(); ++d)
    if (!(m_[d] > 0.0)) m_[d] = std::numeric_limits<double>::max();
}

void CentralDifferenceIntegrator::initialise(StructuralSystem& system, Kinematics& kin) {
  if (!system.lumped_mass()) {
    throw Error("central difference needs a lumped (diagonal) mass: set the mass to lumped");
  }
  load_mass(system);
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
  if (m_.size() != kin.u.size()) load_mass(system);
  const double alpha = system.mass_damping(), beta = system.stiffness_damping();
  const double t1 = kin.time + dt;
  // v_1/2 = v + dt/2 a;  u_1 = u + dt v_1/2
  const auto n = kin.u.size();
  v_half_.resize(n);
  u1_.resize(n);
  for_blocks(static_cast<std::size_t>(n), [&](std::size_t i0, std::size_t i1) {
    const auto b = static_cast<Eigen::Index>(i0), m = static_cast<Eigen::Index>(i1 - i0);
    v_half_.segment(b, m) = kin.v.segment(b, m) + 0.5 * dt * kin.a.segment(b, m);
    u1_.segment(b, m) = kin.u.segment(b, m) + dt * v_half_.segment(b, m);
  });
  system.apply_prescribed(t1, u1_);
  system.internal_forces().set_time(t1, 1.0);  // a rigid indenter moves with the step
  system.internal_forces().evaluate(u1_, kin.f_int, nullptr);
  system.internal_forces().commit();
  system.external_force(t1, f1_);
  if (beta == 0.0) {
    // a_1 = (M^-1 (F_1 - f_int) - alpha v_1/2) / (1 + alpha dt / 2);  v_1 = v_1/2 + dt/2 a_1
    const auto& free = system.dofs().free_dofs();
    for_blocks(free.size(), [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        const auto d = free[i];
        kin.a[d] =
            ((f1_[d] - kin.f_int[d]) / m_[d] - alpha * v_half_[d]) / (1.0 + 0.5 * alpha * dt);
        kin.v[d] = v_half_[d] + 0.5 * dt * kin.a[d];
      }
    });
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
