#pragma once

#include "partita/fem/linear_solver.hpp"
#include "partita/fem/newton_options.hpp"

namespace partita::fem {

enum class MassType { Consistent, Lumped };
// Time integration of step(): implicit Newmark, or explicit central difference (lumped mass).
enum class Integrator { Newmark, CentralDifference };

struct SolverOptions {
  // Newmark: u1 = u0 + dt v0 + dt^2 ((1/2 - beta) a0 + beta a1), v1 = v0 + dt ((1 - gamma) a0
  // + gamma a1). beta = 1/4, gamma = 1/2: average acceleration (unconditionally stable,
  // conserves the energy of an undamped linear system).
  double newmark_beta = 0.25;
  double newmark_gamma = 0.5;
  MassType mass = MassType::Consistent;
  // Rayleigh damping C = alpha M + beta K0. K0 is the stiffness at rest: the assembled K on the
  // linear path, the tangent of the nonlinear operator at u = 0 with the initial history on the
  // nonlinear path (symmetrised). A constant K0 keeps the damping force linear in v, so the
  // Newmark tangent gains a constant beta gamma / (beta_N dt) K0 and the damping work
  // dt v_mid . C v_mid is exact for average acceleration; a current-tangent K_t(u) would make
  // the damping depend on the deformation (and vanish or turn negative where K_t softens).
  double rayleigh_alpha = 0.0;
  double rayleigh_beta = 0.0;
  Integrator integrator = Integrator::Newmark;
  // Newton, load stepping and cut-back of the nonlinear path.
  NewtonOptions newton;
  // The sparse direct solver of static solves, Newmark's K_eff and Newton's tangents:
  // Automatic = CHOLMOD (supernodal) when built in, else Eigen's SimplicialLDLT.
  // Cholmod in a build without it: StructuralSolver throws Error. The ordering is CHOLMOD's.
  LinearSolver linear_solver = LinearSolver::Automatic;
  FillOrdering fill_ordering = FillOrdering::Automatic;
  // The triangular solves of the linear path's static and Newmark steps (linear_solver.hpp).
  SolveThreading solve_threading = SolveThreading::Automatic;
  // The numeric factorisation of a CHOLMOD factor (linear_solver.hpp): the linear path's K_ff and
  // K_eff, and Newton's tangents.
  FactorThreading factor_threading = FactorThreading::Automatic;
  // The nonlinear path (NonlinearOperator: element by element, a sum of OperatorContributions)
  // even for a linear-elastic model. Regions without a law use the small-strain
  // LinearElasticLaw (the same Hex8 modes, as EAS); explicit steps cost more than the linear
  // path's sparse product. Contributions (a rigid indenter's contact) do not need it: the
  // linear path adds them to K u (LinearContributionOperator) for every integrator.
  bool nonlinear_path = false;
  // Mass scaling of central-difference analyses (0: off), as crash analysts use it for
  // quasi-static runs (LS-DYNA's DT2MS < 0, Abaqus/Explicit's fixed mass scaling to a target
  // increment): every element whose stable step dt_e (the element eigenvalue bound of
  // stable_time_step(), unscaled density, free dofs) is below this target gets its density
  // scaled by s_e = (target / dt_e)^2, which raises its dt_e to the target. The lumped mass,
  // kinetic energy, energy balance, energies by part and the stable step all use the scaled
  // mass; body forces (gravity) keep the physical density, so a quasi-static run keeps its
  // static loads. StructuralSolver::added_mass() reports what was added. [s]
  double mass_scaling_time_step = 0.0;
};

}  // namespace partita::fem
