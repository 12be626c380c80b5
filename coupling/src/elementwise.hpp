#pragma once
// Element-by-element kernels of the per-window core (the substep average, the time
// interpolation, the balance audit's sums) over contiguous arrays of doubles.
//
// Each result is the IEEE-rounded value of the same operations in the same order as the plain
// expression in its comment, so the results are bit for bit those of that expression on every
// machine. Where the processor has AVX (checked once at run time), 4 values go through each
// instruction instead of the 2 of the SSE2 baseline the project is compiled for, and 8 with
// AVX-512 in the elementwise kernels (mean_step, interpolate; the sums keep their 4 partial
// sums). No fused multiply-add is used (it would round differently).

#include <cstddef>

namespace partita::coupling::elementwise {

/// mean[i] += (x[i] - mean[i]) / k  (k > 0; divided, or multiplied by 1/k where k is a power of
/// two: then exactly the same numbers).
void mean_step(double* mean, const double* x, std::ptrdiff_t n, double k);

/// out[i] = a[i] + s * (b[i] - a[i])
void interpolate(double* out, const double* a, const double* b, std::ptrdiff_t n, double s);

/// Totals of a 3-component field over weighted points and of its magnitudes, in one pass (the
/// balance audit's sums):
///   total[c]  = sum_i w[i] * v_c[i]                                  (v_0 = x, v_1 = y, v_2 = z)
///   magnitude = sum_i |w[i]| * sqrt((x[i] * x[i] + y[i] * y[i]) + z[i] * z[i])
/// with w[i] = 1 where w is null. Summed in 4 partial sums, row i into sum i mod 4, added
/// as (s0 + s1) + (s2 + s3): the same bits with or without AVX. A NaN or an infinity among
/// the values makes a total NaN or infinite (weights finite: 0 times infinity is NaN).
void weighted_totals3(const double* x, const double* y, const double* z, const double* w,
                      std::ptrdiff_t n, double total[3], double& magnitude);

}  // namespace partita::coupling::elementwise
