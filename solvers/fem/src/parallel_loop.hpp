#pragma once
// f(i) for i in [0, n) on the OpenMP threads (one thread below min_parallel). An exception cannot
// leave a parallel region: the one of the smallest i that threw is kept and rethrown after the
// loop, as a serial loop would have thrown it (the others are dropped). f must write only to
// places of its own i, so the results do not depend on the number of threads.
#include <exception>

namespace partita::fem::detail {

template <class Body>
void parallel_for_first_error(long n, long min_parallel, Body body) {
  std::exception_ptr error;
  long error_at = n;
#pragma omp parallel for schedule(static) if (n >= min_parallel)
  for (long i = 0; i < n; ++i) {
    try {
      body(i);
    } catch (...) {
#pragma omp critical(partita_fem_parallel_for_error)
      if (i < error_at) {
        error_at = i;
        error = std::current_exception();
      }
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace partita::fem::detail
