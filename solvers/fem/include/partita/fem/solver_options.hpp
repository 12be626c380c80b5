#pragma once

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
  // Rayleigh damping C = alpha M + beta K.
  double rayleigh_alpha = 0.0;
  double rayleigh_beta = 0.0;  // linear path only (the nonlinear path rejects it)
  Integrator integrator = Integrator::Newmark;
  // Newton, load stepping and cut-back of the nonlinear path.
  NewtonOptions newton;
};

}  // namespace partita::fem
