#include "partita/coupling/mapping/sparse_mapper.hpp"

#include <algorithm>
#include <cmath>

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
  pad_rows();
  set_meshes(from, to);
}

void SparseMapper::pad_rows() {
  // K minimising the work: K entries a row (a multiply and an add each) plus the extra entries
  // (each a load, a multiply, an add and a store of 3 values: about 3 padded entries)
  const Eigen::Index rows = matrix_.rows();
  const int* outer = matrix_.outerIndexPtr();
  std::vector<double> rows_with(1, 0.0);  // rows_with[n]: rows of n entries
  for (Eigen::Index r = 0; r < rows; ++r) {
    const auto n = static_cast<std::size_t>(outer[r + 1] - outer[r]);
    if (rows_with.size() <= n) rows_with.resize(n + 1, 0.0);
    rows_with[n] += 1.0;
  }
  Padded& p = padded_;
  p = Padded{};
  // Long rows (smoothed maps: ~12 entries) lose little to mispredicted loop exits and much to
  // padding when they are large (10^6 cells, 6 neighbours: 23 -> 28-32 ms a map): there the
  // product stays on the CSR rows (width 0: no padded copy).
  if (matrix_.nonZeros() > 4 * rows) return;
  double best = INFINITY;
  for (std::size_t k = 1; k < std::max<std::size_t>(2, rows_with.size()); ++k) {
    double extra = 0.0;  // entries beyond the first k of each row
    for (std::size_t n = k + 1; n < rows_with.size(); ++n)
      extra += static_cast<double>(n - k) * rows_with[n];
    const double cost = static_cast<double>(rows) * static_cast<double>(k) + 3.0 * extra;
    if (cost < best) best = cost, p.width = static_cast<int>(k);
  }
  const int pad = static_cast<int>(matrix_.cols());  // the zero point
  p.index.assign(static_cast<std::size_t>(rows * p.width), pad);
  p.weight.assign(p.index.size(), 0.0);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (int k = outer[r]; k < outer[r + 1]; ++k) {
      const int slot = k - outer[r];
      if (slot < p.width) {
        p.index[static_cast<std::size_t>(r * p.width + slot)] = matrix_.innerIndexPtr()[k];
        p.weight[static_cast<std::size_t>(r * p.width + slot)] = matrix_.valuePtr()[k];
      } else {
        p.extra_row.push_back(static_cast<int>(r));
        p.extra_index.push_back(matrix_.innerIndexPtr()[k]);
        p.extra_weight.push_back(matrix_.valuePtr()[k]);
      }
    }
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

// csr_times_dense<3>'s product with the three components of a point in one 4-lane register: the
// input is first copied into rows (x, y, z, 0) of `packed` (and a row of zeros after them, the
// padding point), so each entry costs one load of the point instead of three. Rows padded to K
// entries (SparseMapper::Padded): a loop of fixed length, then the extra entries of the longer rows
// added to their sums in order. Each lane does the operations of the scalar loop in its order
// (no FMA): the same numbers, bit for bit.
template <int K>
__attribute__((target("avx"))) void padded_rows3_avx(const int* index, const double* weight,
                                                     int width, Eigen::Index rows, const double* p,
                                                     double* out_x, double* out_y, double* out_z) {
  const int k_end = K > 0 ? K : width;
  for (Eigen::Index r = 0; r < rows; ++r) {
    const int* idx = index + r * k_end;
    const double* w = weight + r * k_end;
    __m256d s = _mm256_setzero_pd();
    for (int k = 0; k < k_end; ++k)
      s = _mm256_add_pd(s,
                        _mm256_mul_pd(_mm256_broadcast_sd(w + k),
                                      _mm256_loadu_pd(p + 4 * static_cast<Eigen::Index>(idx[k]))));
    const __m128d xy = _mm256_castpd256_pd128(s);
    _mm_storel_pd(out_x + r, xy);
    _mm_storeh_pd(out_y + r, xy);
    _mm_store_sd(out_z + r, _mm256_extractf128_pd(s, 1));
  }
}

// The input as rows (x, y, z, 0) of `packed`, and a row of zeros after them (the padding point).
__attribute__((target("avx"))) double* pack3(const double* in, Eigen::Index n,
                                             std::vector<double>& packed) {
  packed.resize(static_cast<std::size_t>(4 * (n + 1)));
  double* p = packed.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    p[4 * j] = in[j];
    p[4 * j + 1] = in[j + n];
    p[4 * j + 2] = in[j + 2 * n];
    p[4 * j + 3] = 0.0;
  }
  for (int c = 0; c < 4; ++c) p[4 * n + c] = 0.0;
  return p;
}

// The same product on the CSR rows (rows of varying length: maps whose rows are long).
__attribute__((target("avx"))) void csr_times_dense3_avx(const SparseMapper::Matrix& w,
                                                         const double* in, double* out,
                                                         Eigen::Index out_stride,
                                                         std::vector<double>& packed) {
  const double* p = pack3(in, w.cols(), packed);
  const int* outer = w.outerIndexPtr();
  const int* inner = w.innerIndexPtr();
  const double* value = w.valuePtr();
  for (Eigen::Index r = 0; r < w.rows(); ++r) {
    __m256d s = _mm256_setzero_pd();
    for (int k = outer[r]; k < outer[r + 1]; ++k)
      s = _mm256_add_pd(
          s, _mm256_mul_pd(_mm256_broadcast_sd(value + k),
                           _mm256_loadu_pd(p + 4 * static_cast<Eigen::Index>(inner[k]))));
    const __m128d xy = _mm256_castpd256_pd128(s);
    _mm_storel_pd(out + r, xy);
    _mm_storeh_pd(out + r + out_stride, xy);
    _mm_store_sd(out + r + 2 * out_stride, _mm256_extractf128_pd(s, 1));
  }
}

__attribute__((target("avx"))) void padded_times_dense3_avx(const SparseMapper::Padded& w,
                                                            Eigen::Index rows, Eigen::Index n,
                                                            const double* in, double* out,
                                                            Eigen::Index out_stride,
                                                            std::vector<double>& packed) {
  const double* p = pack3(in, n, packed);
  double* out_x = out;
  double* out_y = out + out_stride;
  double* out_z = out + 2 * out_stride;
  // widths 1-4 with the entry loop unrolled at compile time, others through the general loop
  using Rows = void (*)(const int*, const double*, int, Eigen::Index, const double*, double*,
                        double*, double*);
  static constexpr Rows kRows[] = {padded_rows3_avx<0>, padded_rows3_avx<1>, padded_rows3_avx<2>,
                                   padded_rows3_avx<3>, padded_rows3_avx<4>};
  kRows[w.width <= 4 ? w.width : 0](w.index.data(), w.weight.data(), w.width, rows, p, out_x, out_y,
                                    out_z);
  for (std::size_t e = 0; e < w.extra_row.size(); ++e) {  // rows ascending, entries in order
    const double v = w.extra_weight[e];
    const double* x = p + 4 * static_cast<Eigen::Index>(w.extra_index[e]);
    const Eigen::Index r = w.extra_row[e];
    out_x[r] += v * x[0];
    out_y[r] += v * x[1];
    out_z[r] += v * x[2];
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
      if (has_avx())
        return padded_.width > 0 ? padded_times_dense3_avx(padded_, matrix_.rows(), matrix_.cols(),
                                                           x, y, out.rows(), packed_)
                                 : csr_times_dense3_avx(matrix_, x, y, out.rows(), packed_);
#endif
      return csr_times_dense<3>(matrix_, x, in.rows(), y, out.rows());
    default:
      for (Eigen::Index c = 0; c < in.cols(); ++c)
        csr_times_dense<1>(matrix_, x + c * in.rows(), in.rows(), y + c * out.rows(), out.rows());
  }
}

bool SparseMapper::arrival_bound(const Eigen::VectorXd& omega, Eigen::VectorXd& u) const {
  if (matrix_.nonZeros() > 0 &&
      Eigen::Map<const Eigen::VectorXd>(matrix_.valuePtr(), matrix_.nonZeros()).minCoeff() < 0.0)
    return false;
  u = matrix_.transpose() * omega;
  return true;
}

}  // namespace partita::coupling
