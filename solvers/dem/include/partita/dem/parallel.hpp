#pragma once
// Thread control for the OpenMP loops of the DEM (no-ops when built without OpenMP).
// Results do not depend on the number of threads: every reduction has a fixed order.

namespace partita::dem {

/// Particles below which a light pass over them (a copy, a monitor's sum, a check) runs on one
/// thread: a fork costs about as much as such a pass over this many particles.
inline constexpr int parallel_pass_min = 16384;

/// Sets the number of threads used by the following steps (n >= 1).
void set_num_threads(int n);
/// The number of threads the next parallel region will use (1 without OpenMP).
int max_threads();
/// The calling thread's number in its team (0 outside a parallel region or without OpenMP).
int thread_num();

}  // namespace partita::dem
