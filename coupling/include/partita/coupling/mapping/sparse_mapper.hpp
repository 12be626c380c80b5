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
//
// For vectors (3 components) on a processor with AVX the product runs on a second copy of W
// made in compute(): every row padded to the same number of entries K (an entry of weight 0 on
// an extra zero point), so the loop over a row's entries has a fixed length and no branch to
// mispredict (rows of an area-balanced map have 1 to 4 entries at random), and the entries
// beyond K of the few longer rows in a list added in a second pass. Each sum gets the same
// products in the same order as in W (a padded entry adds +0, which leaves a sum unchanged):
// the same bits as the plain sparse product.

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
  /// u = W^T omega where every entry of W is >= 0 (see Mapper).
  bool arrival_bound(const Eigen::VectorXd& omega, Eigen::VectorXd& u) const final;

  /// map()'s copy of W for vectors: rows of `width` entries (row-major; padding: weight 0 on
  /// point cols()), and the entries beyond `width` (row, column, weight; rows ascending, in
  /// their order in W).
  struct Padded {
    int width = 0;
    std::vector<int> index;
    std::vector<double> weight;
    std::vector<int> extra_row, extra_index;
    std::vector<double> extra_weight;
  };

 protected:
  /// Consistent interpolation weights from `source` to `target`: a target.size() x
  /// source.size() matrix whose rows sum to 1.
  virtual Matrix interpolation(const Mesh& source, const Mesh& target) const = 0;

 private:
  void pad_rows();  // padded_ from matrix_

  Constraint constraint_;
  Matrix matrix_;
  mutable std::vector<double> packed_;  // map()'s scratch: the input as rows (x, y, z, 0)
  Padded padded_;
};

}  // namespace partita::coupling
