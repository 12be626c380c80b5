#include "parallel_product.hpp"

#include <algorithm>
#include <cstddef>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::fem::detail {
namespace {
// Below this many entries one thread does it (a parallel region costs microseconds).
constexpr Eigen::Index kParallelMinEntries = 1000000;
}  // namespace

void ParallelProduct::add(const SparseMatrix& a, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  if (threads < 2 || a.nonZeros() < kParallelMinEntries || !a.isCompressed()) {
    y.noalias() += a * x;
    return;
  }
  const Eigen::Index cols = a.cols(), rows = a.rows();
  if (outer_ != a.outerIndexPtr() || inner_ != a.innerIndexPtr() || rows_ != rows ||
      cols_ != cols || nnz_ != a.nonZeros() || parts_ != threads) {
    outer_ = a.outerIndexPtr();
    inner_ = a.innerIndexPtr();
    rows_ = rows;
    cols_ = cols;
    nnz_ = a.nonZeros();
    parts_ = threads;
    start_.assign(static_cast<std::size_t>((parts_ + 1) * cols_), 0);
    for (int p = 0; p <= parts_; ++p) {
      const Eigen::Index boundary = rows_ * p / parts_;
      for (Eigen::Index j = 0; j < cols_; ++j) {
        // the inner indices of a compressed column are sorted
        const int* b = inner_ + outer_[j];
        const int* e = inner_ + outer_[j + 1];
        start_[static_cast<std::size_t>(p * cols_ + j)] =
            static_cast<int>(std::lower_bound(b, e, static_cast<int>(boundary)) - inner_);
      }
    }
  }
  const double* v = a.valuePtr();
  const int* idx = a.innerIndexPtr();
  const double* xs = x.data();
  double* ys = y.data();
  const int* start = start_.data();
  const Eigen::Index n = cols_;
  const int parts = parts_;
  // one part per thread (however many the runtime gives, every part is done once)
#pragma omp parallel for schedule(static)
  for (int p = 0; p < parts; ++p) {
    const int* lo = start + static_cast<std::ptrdiff_t>(p) * n;
    const int* hi = lo + n;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double xj = xs[j];
      for (int k = lo[j]; k < hi[j]; ++k) ys[idx[k]] += v[k] * xj;
    }
  }
}

}  // namespace partita::fem::detail
