#include "partita/coupling/elementwise.hpp"

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

// Blocks of 4 rows, row i into lane i mod 4; returns the rows done (a multiple of 4) and leaves
// the lanes' partial sums in acc[quantity][lane] (quantities: x, y, z totals, magnitude, bound).
template <bool kLengths>
__attribute__((target("avx"))) std::ptrdiff_t weighted_totals3_avx(const double* x, const double* y,
                                                                   const double* z, const double* w,
                                                                   const double* u, bool magnitudes,
                                                                   std::ptrdiff_t n,
                                                                   double acc[5][4]) {
  __m256d tx = _mm256_setzero_pd(), ty = tx, tz = tx, tm = tx, tb = tx;
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d sign = _mm256_set1_pd(-0.0);
  std::ptrdiff_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d xx = _mm256_loadu_pd(x + i);
    const __m256d yy = _mm256_loadu_pd(y + i);
    const __m256d zz = _mm256_loadu_pd(z + i);
    const __m256d ww = w ? _mm256_loadu_pd(w + i) : one;
    tx = _mm256_add_pd(tx, _mm256_mul_pd(ww, xx));
    ty = _mm256_add_pd(ty, _mm256_mul_pd(ww, yy));
    tz = _mm256_add_pd(tz, _mm256_mul_pd(ww, zz));
    if constexpr (kLengths) {
      const __m256d xy = _mm256_add_pd(_mm256_mul_pd(xx, xx), _mm256_mul_pd(yy, yy));
      const __m256d n2 = _mm256_add_pd(xy, _mm256_mul_pd(zz, zz));
      // 4 zero vectors (points without load: most of an interface): sqrt(+0) = +0 is skipped
      if (_mm256_movemask_pd(_mm256_cmp_pd(n2, _mm256_setzero_pd(), _CMP_NEQ_UQ)) != 0) {
        const __m256d len = _mm256_sqrt_pd(n2);
        if (magnitudes) tm = _mm256_add_pd(tm, _mm256_mul_pd(_mm256_andnot_pd(sign, ww), len));
        if (u) tb = _mm256_add_pd(tb, _mm256_mul_pd(_mm256_loadu_pd(u + i), len));
      }
    }
  }
  _mm256_storeu_pd(acc[0], tx);
  _mm256_storeu_pd(acc[1], ty);
  _mm256_storeu_pd(acc[2], tz);
  _mm256_storeu_pd(acc[3], tm);
  _mm256_storeu_pd(acc[4], tb);
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

Totals3 weighted_totals3(const double* x, const double* y, const double* z, const double* w,
                         std::ptrdiff_t n, bool magnitudes, const double* u) {
  const bool lengths = magnitudes || u;
  double acc[5][4] = {};  // [x, y, z, magnitude, bound][lane]
  std::ptrdiff_t i = 0;
#ifdef PARTITA_AVX_KERNELS
  if (has_avx())
    i = lengths ? weighted_totals3_avx<true>(x, y, z, w, u, magnitudes, n, acc)
                : weighted_totals3_avx<false>(x, y, z, w, u, magnitudes, n, acc);
#endif
  for (; i < n; ++i) {
    const double wi = w ? w[i] : 1.0;
    const std::ptrdiff_t l = i % 4;
    acc[0][l] += wi * x[i];
    acc[1][l] += wi * y[i];
    acc[2][l] += wi * z[i];
    if (!lengths) continue;
    // + 0 where the vector is zero, as the AVX lanes that skip the square root (|w| 0 = +0)
    const double n2 = (x[i] * x[i] + y[i] * y[i]) + z[i] * z[i];
    if (n2 == 0.0) continue;
    const double len = std::sqrt(n2);
    if (magnitudes) acc[3][l] += std::abs(wi) * len;
    if (u) acc[4][l] += u[i] * len;
  }
  Totals3 t;
  for (int q = 0; q < 3; ++q) t.total[q] = (acc[q][0] + acc[q][1]) + (acc[q][2] + acc[q][3]);
  t.magnitude = (acc[3][0] + acc[3][1]) + (acc[3][2] + acc[3][3]);
  t.bound = (acc[4][0] + acc[4][1]) + (acc[4][2] + acc[4][3]);
  return t;
}

}  // namespace partita::coupling::elementwise
