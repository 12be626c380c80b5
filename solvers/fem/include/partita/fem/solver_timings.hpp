#pragma once
#include <cstddef>

namespace partita::fem {

// Wall-clock seconds spent in each phase, accumulated since construction.
struct SolverTimings {
  double assembly = 0.0;       // element loops into K, M and the load vectors
  double factorisation = 0.0;  // symbolic + numeric factorisations
  double solve = 0.0;          // right-hand sides, triangular solves, updates
  std::size_t factorisations = 0;
  std::size_t solves = 0;
  double factor_nonzeros = 0.0;  // nonzeros of the last linear-path factor L (fill-in measure)
};

}  // namespace partita::fem
