#include "partita/coupling/mapping/sparse_mapper.hpp"

#include "partita/interface/error.hpp"

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
      return csr_times_dense<3>(matrix_, x, in.rows(), y, out.rows());
    default:
      for (Eigen::Index c = 0; c < in.cols(); ++c)
        csr_times_dense<1>(matrix_, x + c * in.rows(), in.rows(), y + c * out.rows(), out.rows());
  }
}

}  // namespace partita::coupling
