#pragma once
// Element-by-element kernels of the per-window core (the substep average, the time
// interpolation, the audit's vector lengths) over contiguous arrays of doubles.
//
// Each result is the IEEE-rounded value of the same operations in the same order as the plain
// expression in its comment, so the results are bit for bit those of that expression on every
// machine. Where the processor has AVX (checked once at run time), 4 values go through each
// instruction instead of the 2 of the SSE2 baseline the project is compiled for: the division
// and the square root, which dominate these loops, then take half the time. No fused
// multiply-add is used (it would round differently).

#include <cstddef>

namespace partita::coupling::elementwise {

/// mean[i] += (x[i] - mean[i]) / k  (k > 0; divided, or multiplied by 1/k where k is a power of
/// two: then exactly the same numbers).
void mean_step(double* mean, const double* x, std::ptrdiff_t n, double k);

/// out[i] = a[i] + s * (b[i] - a[i])
void interpolate(double* out, const double* a, const double* b, std::ptrdiff_t n, double s);

/// out[i] = sqrt((x[i] * x[i] + y[i] * y[i]) + z[i] * z[i])
void norms3(double* out, const double* x, const double* y, const double* z, std::ptrdiff_t n);

}  // namespace partita::coupling::elementwise
