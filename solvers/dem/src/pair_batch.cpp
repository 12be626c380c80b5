// The kernel sets of pair_batch.hpp: pair_batch.inc compiled once per instruction set, each in
// its own namespace inside that set's target region (so nothing outside the region, no inline
// function of a header, is compiled for a set the CPU may lack), and the choice at run time.
#include "partita/dem/pair_batch.hpp"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PARTITA_DEM_WIDE_KERNELS 1
#include <immintrin.h>
#endif

namespace partita::dem {

// vector values passed between the kernels' own (inlined) functions: no ABI concern
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
// GCC 12's _mm512_sqrt_pd starts from _mm512_undefined_pd(), which it then reports as "may be
// used uninitialized" (a false positive of the intrinsic header)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

static_assert(sizeof(PackedParticle) == 128, "pair_batch.inc reads x, r, v, w at fixed offsets");

namespace batch_sse2 {
#define PARTITA_BATCH_LANES 2
#include "pair_batch.inc"
#undef PARTITA_BATCH_LANES
}  // namespace batch_sse2

#if PARTITA_DEM_WIDE_KERNELS
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace batch_avx2 {
#define PARTITA_BATCH_LANES 4
#include "pair_batch.inc"
#undef PARTITA_BATCH_LANES
}  // namespace batch_avx2
#if defined(__clang__)
#pragma clang attribute pop
#pragma clang attribute push(__attribute__((target("avx512f"))), apply_to = function)
#else
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f")
#endif
namespace batch_avx512 {
#define PARTITA_BATCH_LANES 8
#include "pair_batch.inc"
#undef PARTITA_BATCH_LANES
}  // namespace batch_avx512
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

namespace {

constexpr PairBatchKernels sse2_set{"sse2", 2, &batch_sse2::forces<false, false>,
                                    &batch_sse2::forces<true, false>,
    &batch_sse2::forces<false, true>, &batch_sse2::forces<true, true>};
#if PARTITA_DEM_WIDE_KERNELS
constexpr PairBatchKernels avx2_set{"avx2", 4, &batch_avx2::forces<false, false>,
                                    &batch_avx2::forces<true, false>,
    &batch_avx2::forces<false, true>, &batch_avx2::forces<true, true>};
constexpr PairBatchKernels avx512_set{"avx512", 8, &batch_avx512::forces<false, false>,
                                      &batch_avx512::forces<true, false>,
    &batch_avx512::forces<false, true>, &batch_avx512::forces<true, true>};
#endif

}  // namespace

int pair_batch_kernel_sets(const PairBatchKernels** sets, int capacity) {
  int n = 0;
#if PARTITA_DEM_WIDE_KERNELS
  if (__builtin_cpu_supports("avx512f") && n < capacity) sets[n++] = &avx512_set;
  if (__builtin_cpu_supports("avx2") && n < capacity) sets[n++] = &avx2_set;
#endif
  if (n < capacity) sets[n++] = &sse2_set;
  return n;
}

const PairBatchKernels& pair_batch_kernels() {
  static const PairBatchKernels* chosen = [] {
    const PairBatchKernels* sets[3];
    const int n = pair_batch_kernel_sets(sets, 3);
    const char* forced = std::getenv("PARTITA_DEM_PAIR_KERNELS");
    if (forced == nullptr || *forced == '\0') return sets[0];
    for (int k = 0; k < n; ++k)
      if (std::strcmp(forced, sets[k]->name) == 0) return sets[k];
    // a developer's switch, not an input: say once that it is not followed, and go on
    std::string runs;
    for (int k = 0; k < n; ++k) runs += std::string(k ? ", " : "") + sets[k]->name;
    std::fprintf(stderr,
                 "partita: PARTITA_DEM_PAIR_KERNELS=%s is not a kernel set this processor runs "
                 "(it runs: %s); using %s\n",
                 forced, runs.c_str(), sets[0]->name);
    return sets[0];
  }();
  return *chosen;
}

}  // namespace partita::dem
