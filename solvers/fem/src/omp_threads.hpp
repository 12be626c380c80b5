#pragma once
// The OpenMP thread count and the calling thread's number, 1 and 0 in a build without OpenMP.
#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::fem::detail {

inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

inline int thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

}  // namespace partita::fem::detail
