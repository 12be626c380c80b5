#include "supernodal_kernels.hpp"

#include <cmath>
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
#define PARTITA_FMA4(a, b, c) ((a) * (b) + (c))
#define PARTITA_FMA1(a, b, c) ((a) * (b) + (c))
#include "supernodal_kernels.inc"
#undef PARTITA_FMA1
#undef PARTITA_FMA4
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
// one rounding a multiply-add, in the lanes and in the scalar tails alike
#define PARTITA_FMA4(a, b, c) __builtin_ia32_vfmaddpd256((a), (b), (c))
#define PARTITA_FMA1(a, b, c) __builtin_fma((a), (b), (c))
#include "supernodal_kernels.inc"
#undef PARTITA_FMA1
#undef PARTITA_FMA4
#undef PARTITA_KERNELS_NAME
}  // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

namespace {
bool use_avx2() {
#ifdef PARTITA_HAVE_AVX2_KERNELS
  // PARTITA_FEM_SOLVE_KERNELS=sse2 takes the portable set on any processor (the test suite runs
  // the threaded-solve and factorisation tests once with it, so both sets are checked on an
  // AVX2 machine)
  static const bool avx2 = [] {
    const char* forced = std::getenv("PARTITA_FEM_SOLVE_KERNELS");
    if (forced != nullptr && std::strcmp(forced, "sse2") == 0) return false;
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return avx2;
#else
  return false;
#endif
}
}  // namespace

const FactorKernels& factor_kernels() {
#ifdef PARTITA_HAVE_AVX2_KERNELS
  return use_avx2() ? avx2::kFactorKernels : generic::kFactorKernels;
#else
  return generic::kFactorKernels;
#endif
}

const SupernodalKernels& supernodal_kernels() {
#ifdef PARTITA_HAVE_AVX2_KERNELS
  return use_avx2() ? avx2::kKernels : generic::kKernels;
#else
  return generic::kKernels;
#endif
}

}  // namespace partita::fem::detail
