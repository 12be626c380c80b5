#pragma once
// y += A x for a column-major sparse matrix with the rows shared among the OpenMP threads.
// Eigen's own product (y.noalias() += A * x) runs on one thread: it adds column j's entries
// A_ij x_j to y_i for j ascending. Here thread p takes the entries of every column whose rows
// fall in its range, in the same column order, so every y_i receives the same additions in the
// same order: the same bits as Eigen's product, on any number of threads.
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem::detail {

class ParallelProduct {
 public:
  // y += a x (y and x of a's size; y may not alias x)
  void add(const SparseMatrix& a, const Eigen::VectorXd& x, Eigen::VectorXd& y);

 private:
  // the row ranges' first entry in every column, for the matrix and thread count last seen
  const int* outer_ = nullptr;
  const int* inner_ = nullptr;
  Eigen::Index rows_ = 0, cols_ = 0, nnz_ = 0;
  int parts_ = 0;
  std::vector<int> start_;  // (parts_ + 1) x cols_: start_[p * cols_ + j]
};

}  // namespace partita::fem::detail
