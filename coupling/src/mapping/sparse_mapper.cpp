#include "partita/coupling/mapping/sparse_mapper.hpp"

#include "partita/interface/error.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

namespace partita::coupling {

void SparseMapper::compute(const Mesh& from, const Mesh& to) {
  if (from.size() == 0 || to.size() == 0)
    throw Error("mapper '" + name() + "' from mesh '" + from.name() + "' to mesh '" + to.name() +
                "': mesh '" + (from.size() == 0 ? from.name() : to.name()) + "' has no points");
  if (constraint_ == Constraint::consistent) {
    matrix_ = interpolation(from, to);  // |to| x |from|
  } else {
    // W_AB^T: the transpose of the consistent interpolation from `to` back to `from`.
    matrix_ = Matrix(interpolation(to, from).transpose());
  }
  matrix_.makeCompressed();
  set_meshes(from, to);
}

namespace {
// out(r, c) = sum_k W(r, j_k) in(j_k, c) over the stored entries k of row r (CSR), for a fixed
// number of components C: one pass over the row, the C sums in registers, no zeroing pass.
template <int C>
void csr_times_dense(const SparseMapper::Matrix& w, const double* in, Eigen::Index in_stride,
                     double* out, Eigen::Index out_stride) {
  const int* outer = w.outerIndexPtr();
  const int* inner = w.innerIndexPtr();
  const double* value = w.valuePtr();
  for (Eigen::Index r = 0; r < w.rows(); ++r) {
    double sum[C] = {};
    for (int k = outer[r]; k < outer[r + 1]; ++k) {
      const double v = value[k];
      const double* x = in + inner[k];
      for (int c = 0; c < C; ++c) sum[c] += v * x[c * in_stride];
    }
    for (int c = 0; c < C; ++c) out[r + c * out_stride] = sum[c];
  }
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
bool has_avx() {
  static const bool yes = __builtin_cpu_supports("avx");
  return yes;
}

// csr_times_dense<3> with the three components of a point in one 4-lane register: the input is
// first copied into rows (x, y, z, 0) of `packed`, so each stored entry costs one load of the
// point instead of three. Each lane does the operations of the scalar loop in its order (no
// FMA): the same numbers, bit for bit.
__attribute__((target("avx"))) void csr_times_dense3_avx(const SparseMapper::Matrix& w,
                                                         const double* in, Eigen::Index in_stride,
                                                         double* out, Eigen::Index out_stride,
                                                         std::vector<double>& packed) {
  const Eigen::Index n = w.cols();
  packed.resize(static_cast<std::size_t>(4 * n));
  double* p = packed.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    p[4 * j] = in[j];
    p[4 * j + 1] = in[j + in_stride];
    p[4 * j + 2] = in[j + 2 * in_stride];
    p[4 * j + 3] = 0.0;
  }
  const int* outer = w.outerIndexPtr();
  const int* inner = w.innerIndexPtr();
  const double* value = w.valuePtr();
  alignas(32) double sum[4];
  for (Eigen::Index r = 0; r < w.rows(); ++r) {
    __m256d s = _mm256_setzero_pd();
    for (int k = outer[r]; k < outer[r + 1]; ++k)
      s = _mm256_add_pd(
          s, _mm256_mul_pd(_mm256_set1_pd(value[k]),
                           _mm256_loadu_pd(p + 4 * static_cast<Eigen::Index>(inner[k]))));
    _mm256_store_pd(sum, s);
    out[r] = sum[0];
    out[r + out_stride] = sum[1];
    out[r + 2 * out_stride] = sum[2];
  }
}
#define PARTITA_AVX_KERNELS 1
#endif

}  // namespace

void SparseMapper::map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const {
  check_input(in);
  // out = W in  (W = matrix_, |to| x |from|; consistent or the transposed conservative one).
  // Called every window: resize() keeps `out`'s storage when the shape is unchanged.
  out.resize(matrix_.rows(), in.cols());
  const double* x = in.data();
  double* y = out.data();
  switch (in.cols()) {
    case 1:
      return csr_times_dense<1>(matrix_, x, in.rows(), y, out.rows());
    case 2:
      return csr_times_dense<2>(matrix_, x, in.rows(), y, out.rows());
    case 3:
#ifdef PARTITA_AVX_KERNELS
      if (has_avx()) return csr_times_dense3_avx(matrix_, x, in.rows(), y, out.rows(), packed_);
#endif
      return csr_times_dense<3>(matrix_, x, in.rows(), y, out.rows());
    default:
      for (Eigen::Index c = 0; c < in.cols(); ++c)
        csr_times_dense<1>(matrix_, x + c * in.rows(), in.rows(), y + c * out.rows(), out.rows());
  }
}

}  // namespace partita::coupling
