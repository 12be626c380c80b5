#pragma once
#include <string>
#include <vector>

namespace partita::fem {

// Why a Newton solve stopped without converging (None when it converged).
//   RoundOffStall: |R| stopped decreasing at the round-off level of the internal force, above
//     the tolerance (the tolerance asks for more than double precision can give);
//   Stagnation: |R| stopped decreasing well above round-off (an inconsistent tangent, a limit
//     point of the load, or a step too large for the line search);
//   Divergence: |R| grew above its start;
//   SlowConvergence: |R| still decreasing when the iterations ran out;
//   InvertedElement: no trial point was admissible, an element turned inside out;
//   InadmissibleTrial: no trial point was admissible, the material law rejected them (a return
//     mapping that did not converge: typically steps far beyond a limit load);
//   SingularTangent: the tangent could not be factorised (a mechanism or a limit point);
//   NotFinite: the residual became NaN or infinite; InadmissibleStart: the starting point threw.
enum class NewtonFailure {
  None,
  RoundOffStall,
  Stagnation,
  Divergence,
  SlowConvergence,
  InvertedElement,
  InadmissibleTrial,
  SingularTangent,
  NotFinite,
  InadmissibleStart
};

// What one Newton solve did: residual norms |R_k| (k = 0 is the start), energy norms
// |dx_k . R_k-1| (k >= 1), line-search step lengths, the scales of its convergence test (see
// NewtonOptions) at the last iterate, and why it stopped.
struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double reference_force = 0.0;  // force scale F_ref of the relative test at the last iterate
  double round_off = 0.0;        // round-off estimate of the residual at the last iterate
  double tolerance = 0.0;        // max(force_tolerance F_ref, round_off_factor round_off)
  std::vector<double> residual_norms;
  std::vector<double> energy_norms;
  std::vector<double> step_lengths;
  NewtonFailure failure_kind = NewtonFailure::None;
  std::string failure;  // empty when converged
};

}  // namespace partita::fem
