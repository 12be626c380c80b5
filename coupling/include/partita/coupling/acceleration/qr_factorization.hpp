#pragma once
// A thin QR factorisation A = Q R (Q: n x m with orthonormal columns, R: m x m upper
// triangular) built by appending columns with modified Gram-Schmidt and one reorthogonalisation
// ("twice is enough"). append() can refuse a nearly dependent column (QR2 filter of
// Haelterman et al. 2016): the column is dropped when the part orthogonal to the columns
// already in is shorter than `limit` times the column itself.

#include <Eigen/Core>

namespace partita::coupling {

class QrFactorization {
 public:
  /// Start over with columns of `rows` entries.
  void reset(Eigen::Index rows);
  /// Append column v; returns false (and leaves Q, R unchanged) when
  /// |v - Q Q^T v| < limit |v| (limit = 0 accepts every column that is not exactly dependent).
  bool append(const Eigen::VectorXd& v, double limit = 0.0);
  Eigen::Index cols() const { return cols_; }
  Eigen::Index rows() const { return q_.rows(); }
  /// The least-squares solution c of min |A c - b| (R c = Q^T b).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// R(i, i): a column with a tiny diagonal is nearly dependent on the ones before (QR1 filter).
  double diagonal(Eigen::Index i) const { return r_(i, i); }
  /// Frobenius norm of R.
  double r_norm() const { return r_.topLeftCorner(cols_, cols_).norm(); }

 private:
  Eigen::MatrixXd q_;  // rows x capacity
  Eigen::MatrixXd r_;  // capacity x capacity
  Eigen::Index cols_ = 0;
};

}  // namespace partita::coupling
