#include "partita/dem/parallel.hpp"

#include "partita/dem/error.hpp"

#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::dem {

void set_num_threads(int n) {
  if (n < 1) throw Error("set_num_threads: need at least 1 thread, got " + std::to_string(n));
#ifdef _OPENMP
  omp_set_num_threads(n);
#endif
}

int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

int thread_num() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

}  // namespace partita::dem
