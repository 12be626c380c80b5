#pragma once
// body(i) for i in [0, n): on the threads when n reaches parallel_pass_min, else a plain loop,
// outside any parallel construct. (An OpenMP region whose `if` is false still costs about 0.5 us
// to enter and leave: several a step for a small bed's mesh, whose whole step takes a few us.)
// body must write only to places of its own i.
#include "partita/dem/parallel.hpp"

namespace partita::dem::detail {

template <class Index, class Body>
void parallel_pass(Index n, Body&& body) {
  if (n >= static_cast<Index>(parallel_pass_min)) {
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) body(i);
  } else {
    for (Index i = 0; i < n; ++i) body(i);
  }
}

}  // namespace partita::dem::detail
