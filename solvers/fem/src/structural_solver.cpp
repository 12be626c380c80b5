// StructuralSolver: construction, operator contributions and the analyses (static, Newmark,
// central difference), and what the integrators see of the structure (StructuralSystem).
#include "partita/fem/structural_solver.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <cmath>
#include <limits>

#include "partita/fem/error.hpp"
#include "partita/fem/linear_contribution_operator.hpp"
#include "partita/fem/linear_elastic_operator.hpp"
#include "structural_solver_clock.hpp"

namespace partita::fem {

using detail::Clock;
using detail::seconds_since;

StructuralSolver::StructuralSolver(Model model, SolverOptions options)
    : model_(std::move(model)),
      options_(options),
      integrator_(model_.hex8_formulation()),
      static_(options_.newton, options_.linear_solver, options_.fill_ordering,
              options_.factor_threading),
      newmark_(options_.newmark_beta, options_.newmark_gamma, options_.newton,
               options_.linear_solver, options_.fill_ordering, options_.factor_threading) {
  newmark_.set_solve_threading(options_.solve_threading);
  newmark_.set_timings(&timings_);
  static_.set_solve_threading(options_.solve_threading);
  static_.set_timings(&timings_);
  {
    // the static runaway test (a limit load where Newton keeps converging): the model's size
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t n = 0; n < model_.mesh().num_nodes(); ++n) {
      lo = lo.cwiseMin(model_.mesh().node(n));
      hi = hi.cwiseMax(model_.mesh().node(n));
    }
    if (model_.mesh().num_nodes() > 0) static_.set_model_size((hi - lo).norm());
  }
  if (!(options_.newmark_beta > 0.0) || !(options_.newmark_gamma > 0.0)) {
    throw Error("Newmark parameters must be > 0 (beta = 1/4, gamma = 1/2 is the default)");
  }
  if (options_.rayleigh_alpha < 0.0 || options_.rayleigh_beta < 0.0) {
    throw Error("Rayleigh damping coefficients must be >= 0");
  }
  if (resolve(options_.linear_solver) == LinearSolver::Cholmod && !cholmod_available()) {
    throw Error(
        "linear solver 'cholmod': this build of partita has no CHOLMOD (configure with "
        "libsuitesparse-dev installed and -DPARTITA_CHOLMOD=ON); use 'eigen-ldlt' or 'auto'");
  }
  if (options_.integrator == Integrator::CentralDifference && options_.mass != MassType::Lumped) {
    throw Error("the central-difference integrator needs a lumped mass (mass: lumped)");
  }
  if (model_.hex8_formulation() == Hex8Formulation::Reduced) {
    if (options_.integrator != Integrator::CentralDifference)
      throw Error(
          "the reduced Hex8 (hex8: reduced) is an element of central-difference analyses (its "
          "internal force has no tangent); static and Newmark analyses use the EAS Hex8 "
          "(hex8: incompatible-modes)");
    if (options_.rayleigh_beta != 0.0)
      throw Error(
          "the reduced Hex8 (hex8: reduced) has no tangent for the stiffness-proportional "
          "Rayleigh damping's K0: use mass-proportional damping (rayleigh.alpha) with it");
    // the element exists on the nonlinear path (element by element, LinearElasticLaw where the
    // model is linear elastic)
    options_.nonlinear_path = true;
  }
  if (model_.is_linear() && model_.hex8_formulation() == Hex8Formulation::FBar) {
    throw Error(
        "the F-bar Hex8 is an element of the nonlinear path (neo-hooke, j2-plasticity, ...); a "
        "linear-elastic model uses the incompatible-mode Hex8, which does not lock");
  }
  ndof_ = 3 * mesh().num_nodes();
  const auto n = static_cast<Eigen::Index>(ndof_);
  kin_.u = Eigen::VectorXd::Zero(n);
  kin_.v = Eigen::VectorXd::Zero(n);
  kin_.a = Eigen::VectorXd::Zero(n);
  kin_.f = Eigen::VectorXd::Zero(n);
  kin_.f_int = Eigen::VectorXd::Zero(n);
  coupling_force_ = Eigen::VectorXd::Zero(n);
  setup_dofs();
  if (model_.is_linear() && !options_.nonlinear_path) {
    validate_failure_setup();
    assemble_stiffness();
    operator_ = std::make_unique<LinearElasticOperator>(k_);
  } else {
    const auto t0 = Clock::now();
    auto op = std::make_unique<NonlinearOperator>(model_);
    nonlinear_ = op.get();
    operator_ = std::move(op);
    validate_failure_setup();
    if (options_.rayleigh_beta != 0.0) {
      // K0 = K_t(u = 0) with the initial history, symmetrised: the damping stiffness
      Eigen::VectorXd f0;
      operator_->evaluate(Eigen::VectorXd::Zero(n), f0, &k0_);
      k0_ = 0.5 * (SparseMatrix(k0_.transpose()) + k0_);
    }
    timings_.assembly += seconds_since(t0);
  }
  assemble_loads();
  // Start from rest with the prescribed values of t = 0.
  Eigen::VectorXd uc;
  prescribed_values(0.0, uc);
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k)
    kin_.u[dofs_.constrained_dofs()[k]] = uc[static_cast<Eigen::Index>(k)];
  evaluate_external_force(0.0, kin_.f);
  setup_mass_scaling();
  if (nonlinear_ != nullptr || options_.integrator == Integrator::CentralDifference) {
    refresh_internal_force();
  }
}

StructuralSolver::~StructuralSolver() = default;

void StructuralSolver::add_contribution(std::unique_ptr<OperatorContribution> contribution) {
  if (nonlinear_ != nullptr) {
    nonlinear_->add_contribution(std::move(contribution));
  } else {
    // the linear path: K u (one sparse product) plus the contributions; with them the tangent
    // is no longer constant, so static and Newmark take Newton on the sum
    if (linear_sum_ == nullptr) {
      auto op = std::make_unique<LinearContributionOperator>(k_, mesh());
      linear_sum_ = op.get();
      operator_ = std::move(op);
    }
    linear_sum_->add_contribution(std::move(contribution));
  }
  stable_step_ = -1.0;  // the contribution may lower it
  refresh_internal_force();
  acceleration_valid_ = false;
}

// ---------------------------------------------------------------- analyses

void StructuralSolver::solve_static() {
  const auto t0 = Clock::now();
  const double factorisation_before = timings_.factorisation;
  last_was_static_ = true;
  if (nonlinear_ != nullptr) nonlinear_->material().set_dynamic(false);  // rate terms off
  // the operator decides: K_ff factorised once and one solve (a constant tangent), or Newton
  // with load stepping; velocity = acceleration = 0
  static_.solve(*this, kin_, kin_.time);
  // the reactions of the Newton and explicit paths use f_int(u)
  if (uses_newton() || options_.integrator == Integrator::CentralDifference)
    refresh_internal_force();
  update_failures();
  acceleration_valid_ = true;
  ++timings_.solves;
  // the first solve's factorisation is counted in timings_.factorisation
  timings_.solve += seconds_since(t0) - (timings_.factorisation - factorisation_before);
}

void StructuralSolver::step_static(double dt) {
  if (!(dt > 0.0))
    throw Error("step_static: the time step must be positive, got " + std::to_string(dt));
  kin_.time += dt;
  ++steps_;
  solve_static();
}

void StructuralSolver::initialise_acceleration() {
  // M_ff a_f = F_f - (K u + C v)_f   (prescribed accelerations taken as zero)
  evaluate_external_force(kin_.time, kin_.f);
  Eigen::VectorXd r;
  if (!uses_newton()) {
    r = kin_.f - k_ * kin_.u;
  } else {
    refresh_internal_force();
    r = kin_.f - kin_.f_int;
  }
  add_damping_force(kin_.v, -1.0, r);
  Eigen::VectorXd rf(static_cast<Eigen::Index>(dofs_.free_dofs().size()));
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    rf[static_cast<Eigen::Index>(k)] = r[dofs_.free_dofs()[k]];
  Eigen::VectorXd af;
  if (options_.mass == MassType::Lumped) {
    af = rf.cwiseQuotient(Eigen::VectorXd(m_ff_.diagonal()));
  } else {
    // The consistent mass matrix is well conditioned (independent of the mesh size), so
    // Jacobi-preconditioned CG to round-off is far cheaper than a second factorisation.
    Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> cg;
    cg.setTolerance(1e-15);
    cg.setMaxIterations(1000);
    cg.compute(m_ff_);
    af = cg.solve(rf);
    if (cg.info() != Eigen::Success && !(cg.error() < 1e-12)) {
      throw Error("initial acceleration: CG on the mass matrix did not converge (error " +
                  std::to_string(cg.error()) + "); is the density > 0 everywhere?");
    }
  }
  kin_.a.setZero();
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    kin_.a[dofs_.free_dofs()[k]] = af[static_cast<Eigen::Index>(k)];
  acceleration_valid_ = true;
}

void StructuralSolver::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw Error("step(dt): dt must be > 0, got " + std::to_string(dt));
  assemble_mass();
  last_was_static_ = false;
  if (nonlinear_ != nullptr) nonlinear_->material().set_dynamic(true);  // rate terms on
  const auto t0 = Clock::now();
  const double factorisation_before = timings_.factorisation;
  if (options_.integrator == Integrator::CentralDifference) {
    if (!acceleration_valid_) central_.initialise(*this, kin_);
    acceleration_valid_ = true;
    central_.step(*this, kin_, dt);
  } else {
    // Newmark: K_eff factorised once per step size while the operator's tangent is constant
    // (the linear path), Newton otherwise
    if (!acceleration_valid_) initialise_acceleration();
    newmark_.step(*this, kin_, dt);
    if (uses_newton()) refresh_internal_force();
  }
  update_failures();
  ++steps_;
  ++timings_.solves;
  // the step's factorisation (a new step size) is counted in timings_.factorisation
  timings_.solve += seconds_since(t0) - (timings_.factorisation - factorisation_before);
}

void StructuralSolver::add_damping_force(const Eigen::VectorXd& v, double sign,
                                         Eigen::VectorXd& r) const {
  // r += sign (alpha M + beta K0) v
  if (options_.rayleigh_alpha != 0.0) r += (sign * options_.rayleigh_alpha) * (m_ * v);
  if (options_.rayleigh_beta != 0.0)
    r += (sign * options_.rayleigh_beta) * ((nonlinear_ != nullptr ? k0_ : k_) * v);
}

void StructuralSolver::refresh_internal_force() {
  operator_->set_time(kin_.time, 0.0);  // the committed state (a rigid indenter where it is)
  operator_->evaluate(kin_.u, kin_.f_int, nullptr);
}

const SparseMatrix& StructuralSolver::mass() {
  assemble_mass();
  return m_;
}

void StructuralSolver::external_force(double t, Eigen::VectorXd& f) const {
  evaluate_external_force(t, f);
}

void StructuralSolver::apply_prescribed(double t, Eigen::VectorXd& u) const {
  Eigen::VectorXd& uc = prescribed_work_;  // sized once: no allocation per explicit step
  prescribed_values(t, uc);
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k)
    u[dofs_.constrained_dofs()[k]] = uc[static_cast<Eigen::Index>(k)];
}

}  // namespace partita::fem
