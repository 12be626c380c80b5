#pragma once
// Thread control for the OpenMP loops of the DEM (no-ops when built without OpenMP).
// Results do not depend on the number of threads: every reduction has a fixed order.

namespace partita::dem {

/// Sets the number of threads used by the following steps (n >= 1).
void set_num_threads(int n);
/// The number of threads the next parallel region will use (1 without OpenMP).
int max_threads();
/// The calling thread's number in its team (0 outside a parallel region or without OpenMP).
int thread_num();

}  // namespace partita::dem
