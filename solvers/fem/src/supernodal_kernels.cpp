#include "supernodal_kernels.hpp"

#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace partita::fem::detail {

// v4 values passed between the kernels' own (internal, inlined) functions: no ABI concern
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace generic {
#define PARTITA_KERNELS_NAME "sse2"
#include "supernodal_kernels.inc"
#undef PARTITA_KERNELS_NAME
}  // namespace generic

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PARTITA_HAVE_AVX2_KERNELS 1
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#endif
namespace avx2 {
#define PARTITA_KERNELS_NAME "avx2-fma"
#include "supernodal_kernels.inc"
#undef PARTITA_KERNELS_NAME
}  // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

const SupernodalKernels& supernodal_kernels() {
#ifdef PARTITA_HAVE_AVX2_KERNELS
  // PARTITA_FEM_SOLVE_KERNELS=sse2 takes the portable set on any processor (the test suite runs
  // the threaded-solve tests once with it, so both sets are checked on an AVX2 machine)
  static const bool avx2 = [] {
    const char* forced = std::getenv("PARTITA_FEM_SOLVE_KERNELS");
    if (forced != nullptr && std::strcmp(forced, "sse2") == 0) return false;
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return avx2 ? avx2::kKernels : generic::kKernels;
#else
  return generic::kKernels;
#endif
}

}  // namespace partita::fem::detail
