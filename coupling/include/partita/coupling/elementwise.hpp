#pragma once
// Element-by-element kernels of the per-window core (the substep average, the time
// interpolation, the balance audit's sums) over contiguous arrays of doubles.
//
// Each result is the IEEE-rounded value of the same operations in the same order as the plain
// expression in its comment, so the results are bit for bit those of that expression on every
// machine. Where the processor has AVX (checked once at run time), 4 values go through each
// instruction instead of the 2 of the SSE2 baseline the project is compiled for. (8-lane
// AVX-512 versions of mean_step and interpolate measured no faster: these passes are bound by
// L2 traffic.) No fused multiply-add is used (it would round differently).

#include <cstddef>

namespace partita::coupling::elementwise {

/// mean[i] += (x[i] - mean[i]) / k  (k > 0; divided, or multiplied by 1/k where k is a power of
/// two: then exactly the same numbers).
void mean_step(double* mean, const double* x, std::ptrdiff_t n, double k);

/// out[i] = a[i] + s * (b[i] - a[i])
void interpolate(double* out, const double* a, const double* b, std::ptrdiff_t n, double s);

/// What weighted_totals3() sums besides the component totals (null: not summed).
struct Totals3 {
  double total[3] = {};    ///< sum_i w[i] * v_c[i]  (v_0 = x, v_1 = y, v_2 = z)
  double magnitude = 0.0;  ///< sum_i |w[i]| * |v_i|, |v_i| = sqrt((x[i]^2 + y[i]^2) + z[i]^2)
  double bound = 0.0;      ///< sum_i u[i] * |v_i|
};

/// The component totals of a 3-component field over weighted points, and where asked
/// (`magnitudes`; `u` not null) the totals of its lengths |v_i| weighted with |w[i]| and u[i],
/// in one pass (the balance audit's sums). w[i] = 1 where w is null. Summed in 4 partial sums,
/// row i into sum i mod 4, added as (s0 + s1) + (s2 + s3): the same bits with or without AVX.
/// A NaN or an infinity among the values makes a total NaN or infinite (weights finite: 0
/// times infinity is NaN). The lengths take a square root a row: without `magnitudes` and `u`
/// the pass takes none.
Totals3 weighted_totals3(const double* x, const double* y, const double* z, const double* w,
                         std::ptrdiff_t n, bool magnitudes, const double* u = nullptr);

}  // namespace partita::coupling::elementwise
