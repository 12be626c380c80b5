#pragma once

namespace partita::fem {

// Convergence control of the Newton solver and of the load / time stepping around it (the
// members are named as the FEM adapter's YAML keys under analysis.nonlinear).
//
// Converged when the force criterion holds and, after the first iteration, the energy one:
//   |R| <= max(force_tolerance F_ref, round_off_factor r_eps),
//   |dx_k . R_k-1| <= energy_tolerance |dx_1 . R_0|   (or |R| <= round_off_factor r_eps),
// F_ref the force scale of the balance at the current iterate (the norms, over all dofs, of the
// internal force, which includes the reactions, of the external force and of the inertia force:
// the largest), r_eps the round-off estimate of the assembled residual (NonlinearProblem::
// scales()). See NewtonSolver for the reasoning and the references.
struct NewtonOptions {
  int max_iterations = 25;
  double force_tolerance = 1e-8;
  double energy_tolerance = 1e-14;
  // Multiple of the round-off estimate r_eps below which |R| counts as converged whatever the
  // relative test says. r_eps is a bound (absolute values summed); measured stalls of |R| on a
  // steel cantilever (Hex20, every law, loads from 1 mN to 4 kN) lie at 0.004-0.02 r_eps:
  // 0.1 r_eps is 5 times above the highest and still 1e-8 of the forces of a 100 N load.
  double round_off_factor = 0.1;
  // Backtracking line search: halve the step while |R(x + s dx)| > (1 - 1e-4 s) |R(x)|.
  int max_line_search_steps = 6;
  // Also accept a step where the energy slope along dx has fallen, |dx . R(x + s dx)| <=
  // 0.8 |dx . R(x)| (Crisfield's line-search tolerance). On by default: a bending structure
  // that rotates (a steel cantilever at 4 kN in 10 load steps, neo-Hooke) has a first full
  // Newton step that raises |R| a hundredfold (the stiff axial part) while it lowers the energy;
  // the |R| test alone then halves it into a crawl (|R| 218 -> 176 N in 12 iterations), with
  // it Newton takes 3 iterations. Nearly incompressible solids need it for the same reason
  // (Cook's membrane at nu = 0.499: hundreds of cut-backs without, 8 iterations per load step
  // with it).
  bool energy_line_search = true;
  // Static analyses: the load (from the current state to the target) in this many equal
  // increments; a failed increment is halved, at most max_cutbacks times in a row and down to
  // 1/2^max_cutbacks of the initial increment.
  // Implicit dynamics: a failed time step is split in two, at most max_cutbacks levels deep.
  int load_steps = 1;
  int max_cutbacks = 8;
};

}  // namespace partita::fem
