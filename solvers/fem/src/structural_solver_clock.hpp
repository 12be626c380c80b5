#pragma once
// The wall clock of StructuralSolver's timings (SolverTimings), shared by its parts.
#include <chrono>

namespace partita::fem::detail {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace partita::fem::detail
