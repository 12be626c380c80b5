#pragma once
// A thin QR factorisation A = Q R (A: rows x n, Q: rows x n with orthonormal columns, R: n x n
// upper triangular) that is *updated* when a column of A is inserted or deleted, never
// recomputed:
//
// - insert_column(k, v): v is orthogonalised against Q by classical Gram-Schmidt applied twice
//   ("twice is enough"), giving Q^T v = h and the unit vector q of the remainder (length rho).
//   Then [A(:, 0:k), v, A(:, k:n)] = [Q q] [R(:, 0:k) h R(:, k:n); 0 rho 0], and Givens rotations
//   of the rows n, n-1, ..., k+1 restore the triangular form (the same rotations are applied to
//   the columns of [Q q]). O(rows n) work; k = n (append) needs no rotation.
// - delete_column(k): removing column k of R leaves an upper Hessenberg part in columns k..n-2;
//   Givens rotations of the rows (k, k+1), ..., (n-2, n-1) restore triangular form, and the last
//   row of R and the last column of Q are dropped. O(rows n) work.
//
// insert_column can refuse a nearly dependent column (QR2 test of Haelterman et al. 2016): the
// column is not inserted when |v - Q Q^T v| < limit |v|. Since Q is orthonormal, column i of R
// has the norm of column i of A, so |R_ii| / |R(:, i)| is the same test for a column already in.

#include <Eigen/Core>

namespace partita {
class StateArchive;
}  // namespace partita

namespace partita::coupling {

class QrFactorization {
 public:
  /// Start over with no columns of `rows` entries.
  void reset(Eigen::Index rows);
  /// Insert v as column k (0 <= k <= cols(); 0 = front). Returns false and leaves Q, R unchanged
  /// when v is zero or |v - Q Q^T v| < limit |v| (limit = 0 still refuses a column that is
  /// dependent to rounding, |v - Q Q^T v| <= 1e-14 |v|).
  bool insert_column(Eigen::Index k, const Eigen::VectorXd& v, double limit = 0.0);
  /// Insert v as the last column (no rotations).
  bool append(const Eigen::VectorXd& v, double limit = 0.0) {
    return insert_column(cols(), v, limit);
  }
  /// Delete column k (0 <= k < cols()).
  void delete_column(Eigen::Index k);
  /// R <- s R: the factorisation of s A.
  void scale(double s) { r_ *= s; }

  Eigen::Index cols() const { return r_.cols(); }
  Eigen::Index rows() const { return q_.rows(); }
  /// The least-squares solution c of min |A c - b| (R c = Q^T b).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// R(i, i): the part of column i orthogonal to the columns before it (QR1/QR2 filters).
  double diagonal(Eigen::Index i) const { return r_(i, i); }
  /// |R(:, i)| = |A(:, i)|.
  double column_norm(Eigen::Index i) const { return r_.col(i).head(i + 1).norm(); }
  /// Frobenius norm of R (= of A).
  double r_norm() const { return r_.norm(); }
  const Eigen::MatrixXd& q() const { return q_; }
  const Eigen::MatrixXd& r() const { return r_; }
  /// Restart files: Q and R as they are.
  /// Restart files: Q and R, written and read by this one function.
  void serialize(StateArchive& ar);

 private:
  Eigen::MatrixXd q_;  // rows x cols
  Eigen::MatrixXd r_;  // cols x cols, upper triangular
};

}  // namespace partita::coupling
