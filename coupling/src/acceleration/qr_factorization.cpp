#include "partita/coupling/acceleration/qr_factorization.hpp"

#include <cmath>

#include "partita/interface/state_archive.hpp"

namespace partita::coupling {

namespace {

// The rotation G = [c s; -s c] with G [a; b] = [hypot(a, b); 0]. Returns false when a = b = 0.
bool givens(double a, double b, double& c, double& s) {
  const double rho = std::hypot(a, b);
  if (!(rho > 0.0)) return false;
  c = a / rho;
  s = b / rho;
  return true;
}

// Rows i, j of R (columns from `first` on) <- G [row i; row j]; columns i, j of Q <- [q_i q_j] G^T,
// so that Q R is unchanged.
void rotate(Eigen::MatrixXd& q, Eigen::MatrixXd& r, Eigen::Index i, Eigen::Index j,
            Eigen::Index first, double c, double s) {
  const Eigen::Index n = r.cols() - first;
  for (Eigen::Index col = first; col < first + n; ++col) {
    const double a = r(i, col), b = r(j, col);
    r(i, col) = c * a + s * b;
    r(j, col) = -s * a + c * b;
  }
  for (Eigen::Index row = 0; row < q.rows(); ++row) {
    const double a = q(row, i), b = q(row, j);
    q(row, i) = c * a + s * b;
    q(row, j) = -s * a + c * b;
  }
}

}  // namespace

void QrFactorization::reset(Eigen::Index rows) {
  q_.resize(rows, 0);
  r_.resize(0, 0);
}

bool QrFactorization::insert_column(Eigen::Index k, const Eigen::VectorXd& v, double limit) {
  const Eigen::Index n = cols();
  const double norm0 = v.norm();
  if (!(norm0 > 0.0)) return false;
  // Classical Gram-Schmidt, twice ("twice is enough"): u = v - Q h with h = Q^T v accumulated
  // over the passes; a third pass only when the second one still cancelled most of u.
  Eigen::VectorXd h = q_.transpose() * v;
  Eigen::VectorXd u = v - q_ * h;
  double rho = u.norm();
  for (int pass = 1; pass < 3 && n > 0; ++pass) {
    const Eigen::VectorXd dh = q_.transpose() * u;
    u -= q_ * dh;
    h += dh;
    const double before = rho;
    rho = u.norm();
    if (pass == 1 && rho > 0.5 * before) break;
  }
  if (!(rho >= limit * norm0) || rho <= 1e-14 * norm0) return false;

  // [Q q] and [R(:, 0:k) h R(:, k:n); 0 rho 0]
  q_.conservativeResize(Eigen::NoChange, n + 1);
  q_.col(n) = u / rho;
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n + 1, n + 1);
  r.topLeftCorner(n, k) = r_.leftCols(k);
  r.col(k).head(n) = h;
  r(n, k) = rho;
  r.topRightCorner(n, n - k) = r_.rightCols(n - k);
  r_.swap(r);
  // zero column k below the diagonal from the bottom up; row i - 1 of R is zero left of column
  // i - 1 >= k, so the rotations only touch columns k..n
  for (Eigen::Index i = n; i > k; --i) {
    double c = 1.0, s = 0.0;
    if (!givens(r_(i - 1, k), r_(i, k), c, s)) continue;
    rotate(q_, r_, i - 1, i, k, c, s);
    r_(i, k) = 0.0;
  }
  return true;
}

void QrFactorization::delete_column(Eigen::Index k) {
  const Eigen::Index n = cols();
  // drop column k of R: columns k..n-2 are upper Hessenberg
  if (k + 1 < n) r_.middleCols(k, n - k - 1) = r_.rightCols(n - k - 1).eval();
  r_.conservativeResize(Eigen::NoChange, n - 1);
  for (Eigen::Index j = k; j + 1 < n; ++j) {
    double c = 1.0, s = 0.0;
    if (!givens(r_(j, j), r_(j + 1, j), c, s)) continue;
    rotate(q_, r_, j, j + 1, j, c, s);
    r_(j + 1, j) = 0.0;
  }
  // the last row of R is now zero: drop it with the last column of Q
  r_.conservativeResize(n - 1, Eigen::NoChange);
  q_.conservativeResize(Eigen::NoChange, n - 1);
}

Eigen::VectorXd QrFactorization::solve(const Eigen::VectorXd& b) const {
  const Eigen::VectorXd qtb = q_.transpose() * b;
  // back substitution R c = Q^T b
  return r_.triangularView<Eigen::Upper>().solve(qtb);
}

void QrFactorization::serialize(StateArchive& ar) {
  ar.io(q_);
  ar.io(r_);
  if (ar.reading() && (q_.cols() != r_.cols() || r_.rows() != r_.cols()))
    ar.fail("a QR factorisation of matching size");
}

}  // namespace partita::coupling
