#include "partita/fem/newmark_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// R(u_1) = F_1 - f_int(u_1) - M (a_1 + alpha v_1) - beta_R K0 v_1 on the free dofs, with
// a_1 = c0 (u_1 - u) - c2 v - c3 a and v_1 = v + dt ((1 - gamma) a + gamma a_1).
// Adds c B to A in place when both have the same sparsity pattern (checked once per pair of
// matrices and remembered in `checked` / `same`): the values then line up entry by entry and the
// sum is the one Eigen's sparse sum would give, without building a new matrix.
// Returns false when it had to build a new matrix (the patterns differ).
bool add_scaled(SparseMatrix& a, double c, const SparseMatrix& b, bool& checked, bool& same) {
  if (!checked) {
    same = a.isCompressed() && b.isCompressed() && a.rows() == b.rows() && a.cols() == b.cols() &&
           a.nonZeros() == b.nonZeros() &&
           std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1, b.outerIndexPtr()) &&
           std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
    checked = true;
  }
  if (same) {
    double* av = a.valuePtr();
    const double* bv = b.valuePtr();
    for (Eigen::Index i = 0; i < a.nonZeros(); ++i) av[i] += c * bv[i];
    return true;
  }
  a += c * b;
  return false;
}

class NewmarkProblem final : public NonlinearProblem {
 public:
  NewmarkProblem(StructuralSystem& s, const Kinematics& kin, const Eigen::VectorXd& f1,
                 Eigen::VectorXd& u1, double beta, double gamma, double dt,
                 NewmarkIntegrator::Work& work)
      : s_(s), kin_(kin), f1_(f1), u1_(u1), gamma_(gamma), dt_(dt), w_(work) {
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
    // the operator assembles into its own pattern: a K_full whose pattern a sum has changed is
    // made anew
    if (w_.k_full_foreign) {
      w_.k_full = SparseMatrix();
      w_.k_full_foreign = false;
    }
    s_.internal_forces().evaluate(u1_, w_.f_int, k != nullptr ? &w_.k_full : nullptr);
    velocity_acceleration(w_.v1, w_.a1);
    const double alpha = s_.mass_damping(), beta_r = s_.stiffness_damping();
    const SparseMatrix& m = s_.mass();
    // F_1 - f_int - M (a_1 + alpha v_1) [- beta_R K0 v_1]
    // one expression, as Eigen evaluates it into a new vector (the products accumulated into
    // the sum), here into kept storage: the same bits, no allocation
    if (beta_r == 0.0) {
      w_.rhs.noalias() = f1_ - w_.f_int - m * (w_.a1 + alpha * w_.v1);
    } else {
      w_.rhs.noalias() =
          f1_ - w_.f_int - m * (w_.a1 + alpha * w_.v1) - beta_r * (s_.damping_stiffness() * w_.v1);
    }
    s_.dofs().gather_free(w_.rhs, r);
    // F_ref = max(|F_1|, |f_int|, |F_1 - f_int - R_all|) (the last: the inertia and damping
    // forces); r_eps = the operator's bound + eps (|F_1| + the inertia term's bound, whose
    // a_1 = c0 (u_1 - u) - ... cancels digits: eps c0 m_max (|u_1| + |u|), m_max the largest
    // absolute row sum of M)
    {
      const double eps = std::numeric_limits<double>::epsilon();
      const double nf = f1_.norm(), ni = w_.f_int.norm();
      double inertia2 = 0.0;  // (a loop, not an expression: no temporary vector per call)
      for (Eigen::Index i = 0; i < f1_.size(); ++i) {
        const double t = f1_[i] - w_.f_int[i] - w_.rhs[i];
        inertia2 += t * t;
      }
      const double inertia = std::sqrt(inertia2);
      if (w_.mass_row_max < 0.0) {
        w_.mass_row_max = 0.0;
        const Eigen::VectorXd rows = m.cwiseAbs() * Eigen::VectorXd::Ones(m.cols());
        if (rows.size() > 0) w_.mass_row_max = rows.maxCoeff();
      }
      scales_.force = std::max({nf, ni, inertia});
      scales_.round_off =
          s_.internal_forces().round_off() +
          eps * (nf + inertia + c0_ * w_.mass_row_max * (u1_.norm() + kin_.u.norm()));
    }
    if (k == nullptr) return;
    // K = K_t + (c0 + alpha gamma c2) M + beta_R gamma c2 K0   (d v_1 / d u_1 = gamma c2)
    if (!add_scaled(w_.k_full, c0_ + alpha * gamma_ * c2_, m, w_.mass_pattern_checked,
                    w_.mass_pattern_same))
      w_.k_full_foreign = true;
    if (beta_r != 0.0 && !add_scaled(w_.k_full, beta_r * gamma_ * c2_, s_.damping_stiffness(),
                                     w_.k0_pattern_checked, w_.k0_pattern_same))
      w_.k_full_foreign = true;
    s_.dofs().split(w_.k_full, *k, w_.k_fc);
  }
  ResidualScales scales() const override { return scales_; }

 private:
  StructuralSystem& s_;
  const Kinematics& kin_;
  const Eigen::VectorXd& f1_;
  Eigen::VectorXd& u1_;
  double gamma_, dt_, c0_ = 0, c2_ = 0, c3_ = 0;
  NewmarkIntegrator::Work& w_;
  ResidualScales scales_;
};

}  // namespace

NewmarkIntegrator::NewmarkIntegrator(double beta, double gamma, NewtonOptions options,
                                     LinearSolver linear_solver, FillOrdering ordering,
                                     FactorThreading factor_threading)
    : beta_(beta),
      gamma_(gamma),
      newton_(options, linear_solver, ordering, factor_threading),
      linear_solver_(linear_solver),
      ordering_(ordering),
      factor_threading_(factor_threading) {}

// ---- constant tangent: K_eff factorised once per step size ----

void NewmarkIntegrator::factorise(StructuralSystem& system, double dt) {
  const SparseMatrix* k = system.internal_forces().constant_tangent();
  if (k == nullptr) return;  // Newton: its own factorisations
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (k_ff_.rows() == 0 && system.dofs().free_dofs().size() > 0) {
    system.dofs().split(*k, k_ff_, k_fc_);
    system.dofs().split(system.mass(), m_ff_, m_fc_);
  }
  const double c0 = 1.0 / (beta_ * dt * dt), c1 = gamma_ / (beta_ * dt);
  // K_eff = K + gamma/(beta dt) C + 1/(beta dt^2) M with C = alpha M + beta_R K
  const double sk = 1.0 + c1 * system.stiffness_damping();
  const double sm = c0 + c1 * system.mass_damping();
  const SparseMatrix keff_ff = sk * k_ff_ + sm * m_ff_;
  keff_fc_ = sk * k_fc_ + sm * m_fc_;
  // symbolic analysis once (the pattern of K_eff does not depend on dt), numeric per dt
  if (!factor_) {
    factor_ = std::make_unique<SparseFactorisation>(linear_solver_, ordering_);
    factor_->set_solve_threading(solve_threading_);
    factor_->set_factor_threading(factor_threading_);
    factor_->analyze(keff_ff);
  }
  factorize_or_throw(*factor_, keff_ff, "effective matrix K_eff");
  factor_dt_ = dt;
  if (timings_ != nullptr) {
    timings_->factor_nonzeros = factor_->factor_nonzeros();
    ++timings_->factorisations;
    timings_->factorisation += std::chrono::duration<double>(Clock::now() - t0).count();
  }
}

void NewmarkIntegrator::step_constant_tangent(StructuralSystem& system, Kinematics& kin,
                                              const SparseMatrix& k, double dt) {
  if (!(factor_dt_ > 0.0) || std::abs(dt - factor_dt_) > 1e-9 * factor_dt_) factorise(system, dt);
  const double h = factor_dt_;  // the clock advances by dt
  const double beta = beta_, gamma = gamma_;
  const double alpha_r = system.mass_damping(), beta_r = system.stiffness_damping();
  const double c0 = 1.0 / (beta * h * h), c1 = gamma / (beta * h), c2 = 1.0 / (beta * h);
  const double c3 = 0.5 / beta - 1.0, c4 = gamma / beta - 1.0, c5 = h * (0.5 * gamma / beta - 1.0);
  const double t1 = kin.time + dt;
  const DofPartition& dofs = system.dofs();
  const SparseMatrix& m = system.mass();

  // work vectors are members: no allocation once sized
  Work& w = work_;
  system.external_force(t1, w.f1);
  // K_eff u1 = F1 + M (c0 u + c2 v + c3 a) + C (c1 u + c4 v + c5 a)
  w.pm = c0 * kin.u + c2 * kin.v + c3 * kin.a;
  w.rhs = w.f1;
  if (alpha_r != 0.0 || beta_r != 0.0) {
    w.pc = c1 * kin.u + c4 * kin.v + c5 * kin.a;
    w.pm += alpha_r * w.pc;
    w.rhs.noalias() += m * w.pm;
    if (beta_r != 0.0) {
      w.pc *= beta_r;
      w.rhs.noalias() += k * w.pc;
    }
  } else {
    w.rhs.noalias() += m * w.pm;
  }
  system.prescribed_values(t1, w.uc);
  w.rf.resize(static_cast<Eigen::Index>(dofs.free_dofs().size()));
  for (std::size_t i = 0; i < dofs.free_dofs().size(); ++i)
    w.rf[static_cast<Eigen::Index>(i)] = w.rhs[dofs.free_dofs()[i]];
  if (w.uc.size() > 0 && w.uc.cwiseAbs().maxCoeff() > 0.0) w.rf.noalias() -= keff_fc_ * w.uc;
  factor_->solve(w.rf, w.uf);

  w.u1.resize(kin.u.size());
  for (std::size_t i = 0; i < dofs.free_dofs().size(); ++i)
    w.u1[dofs.free_dofs()[i]] = w.uf[static_cast<Eigen::Index>(i)];
  for (std::size_t i = 0; i < dofs.constrained_dofs().size(); ++i)
    w.u1[dofs.constrained_dofs()[i]] = w.uc[static_cast<Eigen::Index>(i)];
  // a1 = c0 (u1 - u) - c2 v - c3 a;  v1 = v + h ((1 - gamma) a + gamma a1)
  w.a1 = c0 * (w.u1 - kin.u) - c2 * kin.v - c3 * kin.a;
  kin.v += h * ((1.0 - gamma) * kin.a + gamma * w.a1);
  kin.external_work += 0.5 * (kin.f + w.f1).dot(w.u1 - kin.u);
  kin.u.swap(w.u1);
  kin.a.swap(w.a1);
  kin.f.swap(w.f1);
  kin.time = t1;
}

// ---- Newton ----

bool NewmarkIntegrator::try_step(StructuralSystem& system, Kinematics& kin, double dt) {
  const double t1 = kin.time + dt;
  Work& w = work_;
  w.u1 = kin.u;
  system.external_force(t1, w.f1);
  system.apply_prescribed(t1, w.u1);
  system.internal_forces().set_time(t1, 1.0);  // a rigid indenter moves with the step
  system.dofs().gather_free(w.u1, w.x);
  NewmarkProblem problem(system, kin, w.f1, w.u1, beta_, gamma_, dt, w);
  last_ = newton_.solve(problem, w.x, 0.0);
  step_iterations_ += last_.iterations;
  if (!last_.converged) return false;
  system.dofs().scatter_free(w.x, w.u1);
  system.internal_forces().evaluate(w.u1, w.f_int, nullptr);
  system.internal_forces().commit();
  problem.velocity_acceleration(w.v1, w.a1);
  // prescribed dofs: Newmark velocity and acceleration of the prescribed motion
  w.v_mid = 0.5 * (kin.v + w.v1);
  // dt v_mid . C v_mid: exact for average acceleration (the mean of the equations at n and
  // n+1 times u_1 - u = dt v_mid)
  w.m_v.noalias() = system.mass() * w.v_mid;
  kin.damping_work += dt * system.mass_damping() * w.v_mid.dot(w.m_v);
  if (system.stiffness_damping() != 0.0) {
    w.m_v.noalias() = system.damping_stiffness() * w.v_mid;
    kin.damping_work += dt * system.stiffness_damping() * w.v_mid.dot(w.m_v);
  }
  kin.external_work += 0.5 * (kin.f + w.f1).dot(w.u1 - kin.u);
  kin.u = w.u1;
  kin.v = w.v1;
  kin.a = w.a1;
  kin.f = w.f1;
  kin.time = t1;
  return true;
}

void NewmarkIntegrator::step_with_cutback(StructuralSystem& system, Kinematics& kin, double dt,
                                          int depth) {
  if (try_step(system, kin, dt)) return;
  if (progress_ && depth < newton_.options().max_cutbacks) {
    std::ostringstream line;
    line << "Newmark step at t = " << kin.time << " of " << dt << " s failed (" << last_.failure
         << "); cut-back " << depth + 1 << ": two steps of " << 0.5 * dt << " s";
    progress_(line.str());
  }
  if (depth >= newton_.options().max_cutbacks) {
    std::ostringstream msg;
    msg << "Newmark Newton solver failed at t = " << kin.time << " with a step of " << dt
        << " s after " << depth << " cut-backs (halvings): " << last_.failure
        << "; last residual |R| = "
        << (last_.residual_norms.empty() ? 0.0 : last_.residual_norms.back()) << " N (tolerance "
        << last_.tolerance << " N). "
        << (last_.failure_kind == NewtonFailure::RoundOffStall
                ? "The residual cannot go lower in double precision: raise force_tolerance or "
                  "round_off_factor (smaller steps do not help)"
                : "Use a smaller time step or check the material and supports");
    throw Error(msg.str());
  }
  step_with_cutback(system, kin, 0.5 * dt, depth + 1);
  step_with_cutback(system, kin, 0.5 * dt, depth + 1);
}

void NewmarkIntegrator::step(StructuralSystem& system, Kinematics& kin, double dt) {
  step_iterations_ = 0;
  if (const SparseMatrix* k = system.internal_forces().constant_tangent()) {
    step_constant_tangent(system, kin, *k, dt);
    return;
  }
  step_with_cutback(system, kin, dt, 0);
}

}  // namespace partita::fem
