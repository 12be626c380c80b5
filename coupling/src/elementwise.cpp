#include "elementwise.hpp"

#include <cmath>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PARTITA_AVX_KERNELS 1
#include <immintrin.h>
#endif

namespace partita::coupling::elementwise {

namespace {

bool power_of_two(double k) {
  int e = 0;
  return std::frexp(k, &e) == 0.5;
}

#ifdef PARTITA_AVX_KERNELS
bool has_avx() {
  static const bool yes = __builtin_cpu_supports("avx");
  return yes;
}

// The same operations, 4 lanes at a time; the remainder (n mod 4) in the scalar loops below.
__attribute__((target("avx"))) std::ptrdiff_t mean_step_avx(double* mean, const double* x,
                                                            std::ptrdiff_t n, double k,
                                                            bool multiply) {
  const __m256d kk = _mm256_set1_pd(multiply ? 1.0 / k : k);
  std::ptrdiff_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d m = _mm256_loadu_pd(mean + i);
    const __m256d d = _mm256_sub_pd(_mm256_loadu_pd(x + i), m);
    // Where the 4 differences are all 0 (no change: interface points without contact), d / k
    // is d itself (a zero of the same sign): the division is skipped, the sum still done.
    const bool all_zero =
        _mm256_movemask_pd(_mm256_cmp_pd(d, _mm256_setzero_pd(), _CMP_NEQ_UQ)) == 0;
    if (all_zero)
      _mm256_storeu_pd(mean + i, _mm256_add_pd(m, d));
    else if (multiply)
      _mm256_storeu_pd(mean + i, _mm256_add_pd(m, _mm256_mul_pd(d, kk)));
    else
      _mm256_storeu_pd(mean + i, _mm256_add_pd(m, _mm256_div_pd(d, kk)));
  }
  return i;
}

__attribute__((target("avx"))) std::ptrdiff_t interpolate_avx(double* out, const double* a,
                                                              const double* b, std::ptrdiff_t n,
                                                              double s) {
  const __m256d ss = _mm256_set1_pd(s);
  std::ptrdiff_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d aa = _mm256_loadu_pd(a + i);
    const __m256d d = _mm256_sub_pd(_mm256_loadu_pd(b + i), aa);
    _mm256_storeu_pd(out + i, _mm256_add_pd(aa, _mm256_mul_pd(ss, d)));
  }
  return i;
}

__attribute__((target("avx"))) std::ptrdiff_t norms3_avx(double* out, const double* x,
                                                         const double* y, const double* z,
                                                         std::ptrdiff_t n) {
  std::ptrdiff_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d xx = _mm256_loadu_pd(x + i);
    const __m256d yy = _mm256_loadu_pd(y + i);
    const __m256d zz = _mm256_loadu_pd(z + i);
    const __m256d xy = _mm256_add_pd(_mm256_mul_pd(xx, xx), _mm256_mul_pd(yy, yy));
    const __m256d n2 = _mm256_add_pd(xy, _mm256_mul_pd(zz, zz));
    // 4 zero vectors (+0: a sum of squares): sqrt(+0) = +0, the square root is skipped
    const bool all_zero =
        _mm256_movemask_pd(_mm256_cmp_pd(n2, _mm256_setzero_pd(), _CMP_NEQ_UQ)) == 0;
    if (all_zero)
      _mm256_storeu_pd(out + i, n2);
    else
      _mm256_storeu_pd(out + i, _mm256_sqrt_pd(n2));
  }
  return i;
}
#endif

}  // namespace

void mean_step(double* mean, const double* x, std::ptrdiff_t n, double k) {
  const bool multiply = power_of_two(k);  // x / k = x (1/k) exactly
  const double r = 1.0 / k;
  std::ptrdiff_t i = 0;
#ifdef PARTITA_AVX_KERNELS
  if (has_avx()) i = mean_step_avx(mean, x, n, k, multiply);
#endif
  if (multiply)
    for (; i < n; ++i) mean[i] += (x[i] - mean[i]) * r;
  else
    for (; i < n; ++i) mean[i] += (x[i] - mean[i]) / k;
}

void interpolate(double* out, const double* a, const double* b, std::ptrdiff_t n, double s) {
  std::ptrdiff_t i = 0;
#ifdef PARTITA_AVX_KERNELS
  if (has_avx()) i = interpolate_avx(out, a, b, n, s);
#endif
  for (; i < n; ++i) out[i] = a[i] + s * (b[i] - a[i]);
}

void norms3(double* out, const double* x, const double* y, const double* z, std::ptrdiff_t n) {
  std::ptrdiff_t i = 0;
#ifdef PARTITA_AVX_KERNELS
  if (has_avx()) i = norms3_avx(out, x, y, z, n);
#endif
  for (; i < n; ++i) out[i] = std::sqrt((x[i] * x[i] + y[i] * y[i]) + z[i] * z[i]);
}

}  // namespace partita::coupling::elementwise
