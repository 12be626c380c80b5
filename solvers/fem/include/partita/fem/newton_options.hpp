#pragma once

namespace partita::fem {

// Convergence control of the Newton solver and of the load / time stepping around it.
struct NewtonOptions {
  int max_iterations = 25;
  // Converged when |R| <= force_tolerance * max(reference force, |R_0|) and (after the first
  // iteration) |dx_k . R_k-1| <= energy_tolerance * |dx_1 . R_0|.
  double force_tolerance = 1e-8;
  double energy_tolerance = 1e-14;
  // Backtracking line search: halve the step while |R(x + s dx)| > (1 - 1e-4 s) |R(x)|.
  int max_line_search_steps = 6;
  // Also accept a step where the energy slope along dx has fallen, |dx . R(x + s dx)| <=
  // 0.8 |dx . R(x)| (Crisfield's line-search tolerance). Nearly incompressible solids need it:
  // there the full Newton step of an increment raises |R| (dominated by the stiff volumetric
  // part) while it lowers the energy, and the |R| test alone halves it into linear convergence
  // (Cook's membrane at nu = 0.499: hundreds of cut-backs without, 8 iterations per load step
  // with it). Off by default: it changes the path of the iterates of existing analyses.
  bool energy_line_search = false;
  // Static analyses: the load (from the current state to the target) in this many equal
  // increments; a failed increment is halved, at most max_cutbacks times in a row.
  // Implicit dynamics: a failed time step is split in two, at most max_cutbacks levels deep.
  int load_steps = 1;
  int max_cutbacks = 8;
};

}  // namespace partita::fem
