#include "partita/coupling/acceleration/qr_factorization.hpp"

namespace partita::coupling {

void QrFactorization::reset(Eigen::Index rows) {
  q_.resize(rows, 0);
  r_.resize(0, 0);
  cols_ = 0;
}

bool QrFactorization::append(const Eigen::VectorXd& v, double limit) {
  const double norm0 = v.norm();
  if (!(norm0 > 0.0)) return false;
  // Modified Gram-Schmidt, twice: u = v - Q (Q^T v), h accumulates the projections.
  Eigen::VectorXd u = v;
  Eigen::VectorXd h = Eigen::VectorXd::Zero(cols_);
  for (int pass = 0; pass < 2; ++pass) {
    for (Eigen::Index j = 0; j < cols_; ++j) {
      const double p = q_.col(j).dot(u);
      u -= p * q_.col(j);
      h(j) += p;
    }
  }
  const double rho = u.norm();
  if (!(rho > limit * norm0) || rho <= 1e-14 * norm0) return false;
  q_.conservativeResize(Eigen::NoChange, cols_ + 1);
  q_.col(cols_) = u / rho;
  r_.conservativeResize(cols_ + 1, cols_ + 1);
  r_.row(cols_).setZero();
  r_.col(cols_).head(cols_) = h;
  r_(cols_, cols_) = rho;
  ++cols_;
  return true;
}

Eigen::VectorXd QrFactorization::solve(const Eigen::VectorXd& b) const {
  const Eigen::VectorXd qtb = q_.leftCols(cols_).transpose() * b;
  // back substitution R c = Q^T b
  return r_.topLeftCorner(cols_, cols_).triangularView<Eigen::Upper>().solve(qtb);
}

}  // namespace partita::coupling
