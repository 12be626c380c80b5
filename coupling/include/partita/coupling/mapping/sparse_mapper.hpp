#pragma once
// A mapper whose operator is an explicit sparse matrix (template method: this base owns
// compute() and map(); a subclass only supplies the consistent interpolation weights).
//
//   consistent   from A to B:  out_B = W_BA in_A,    W_BA = interpolation(A, B)
//   conservative from A to B:  out_B = W_AB^T in_A,  W_AB = interpolation(B, A)
//
// Either way the stored matrix is |B| x |A|, row-major, so map() is one sparse product with
// no allocation beyond `out` (and, for 3 components on a processor with AVX, a copy of the
// input with each point's x, y, z side by side, kept between calls).

#include <vector>

#include <Eigen/SparseCore>

#include "partita/coupling/mapping/mapper.hpp"

namespace partita::coupling {

class SparseMapper : public Mapper {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  explicit SparseMapper(Constraint constraint) : constraint_(constraint) {}

  void compute(const Mesh& from, const Mesh& to) final;
  void map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const final;
  Constraint constraint() const final { return constraint_; }

  /// The operator of map(): target.size() x source.size().
  const Matrix& matrix() const { return matrix_; }

 protected:
  /// Consistent interpolation weights from `source` to `target`: a target.size() x
  /// source.size() matrix whose rows sum to 1.
  virtual Matrix interpolation(const Mesh& source, const Mesh& target) const = 0;

 private:
  Constraint constraint_;
  Matrix matrix_;
  mutable std::vector<double> packed_;  // map()'s scratch: the input as rows (x, y, z, 0)
};

}  // namespace partita::coupling
