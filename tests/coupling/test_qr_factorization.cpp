// The updated QR factorisation (Givens rotations on insertion and deletion) and its use in
// IQN-ILS: Q stays orthonormal, Q R the current matrix, the filters see the updated R.
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/acceleration/qr_factorization.hpp"

using namespace partita::coupling;

namespace {

Eigen::MatrixXd stack_columns(const std::vector<Eigen::VectorXd>& cols, Eigen::Index rows) {
  Eigen::MatrixXd a(rows, static_cast<Eigen::Index>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j) a.col(static_cast<Eigen::Index>(j)) = cols[j];
  return a;
}

// |Q^T Q - I|, |Q R - A| / |A| and the largest entry below the diagonal of R
void check_factorisation(const QrFactorization& qr, const Eigen::MatrixXd& a) {
  REQUIRE(qr.cols() == a.cols());
  REQUIRE(qr.rows() == a.rows());
  const Eigen::Index n = a.cols();
  if (n == 0) return;
  const double orth =
      (qr.q().transpose() * qr.q() - Eigen::MatrixXd::Identity(n, n)).lpNorm<Eigen::Infinity>();
  const double err = (qr.q() * qr.r() - a).norm() / a.norm();
  const double lower = qr.r().triangularView<Eigen::StrictlyLower>().toDenseMatrix().norm();
  INFO("columns " << n << ": |Q^T Q - I|_max " << orth << ", |QR - A| / |A| " << err);
  CHECK(orth < 1e-12);
  CHECK(err < 1e-12);
  CHECK(lower == 0.0);
}

}  // namespace

TEST_CASE("QR factorisation stays orthonormal and exact under random insertions and deletions",
          "[coupling][acceleration][qr]") {
  const Eigen::Index m = 60;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_column = [&] {
    Eigen::VectorXd v(m);
    for (Eigen::Index i = 0; i < m; ++i) v(i) = u(rng);
    // entries of quite different size, as coupling data scaled per field are
    v.head(m / 3) *= 100.0;
    return v;
  };
  QrFactorization qr;
  qr.reset(m);
  std::vector<Eigen::VectorXd> cols;
  for (int step = 0; step < 400; ++step) {
    const int n = static_cast<int>(cols.size());
    const double p = u(rng);
    // mostly insert at the front (as IQN-ILS does) while there are few columns, else delete
    const bool insert = n < 3 || (n < 25 && p > -0.3);
    if (insert) {
      const int k = (step % 3 == 0) ? std::uniform_int_distribution<int>(0, n)(rng) : 0;
      const Eigen::VectorXd v = random_column();
      REQUIRE(qr.insert_column(k, v));
      cols.insert(cols.begin() + k, v);
    } else {
      const int k = (step % 2 == 0) ? n - 1 : std::uniform_int_distribution<int>(0, n - 1)(rng);
      qr.delete_column(k);
      cols.erase(cols.begin() + k);
    }
    check_factorisation(qr, stack_columns(cols, m));
    if (!cols.empty()) {
      // least squares through the factorisation agrees with the normal equations' solution
      const Eigen::MatrixXd a = stack_columns(cols, m);
      const Eigen::VectorXd b = random_column();
      const Eigen::VectorXd c = qr.solve(b);
      CHECK((a.transpose() * (a * c - b)).norm() <= 1e-9 * a.norm() * b.norm());
    }
  }
}

TEST_CASE("QR insertion refuses zero and dependent columns and leaves the factorisation as is",
          "[coupling][acceleration][qr]") {
  const Eigen::Index m = 8;
  QrFactorization qr;
  qr.reset(m);
  const Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(m, 1.0, 2.0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(m, -1.0, 3.0).array().square();
  REQUIRE(qr.insert_column(0, a));
  REQUIRE(qr.insert_column(0, b));
  CHECK_FALSE(qr.insert_column(0, Eigen::VectorXd::Zero(m)));
  CHECK_FALSE(qr.insert_column(1, 2.0 * a - 0.5 * b));  // exactly dependent
  Eigen::VectorXd near = a + b;
  near(3) += 1e-6;
  CHECK_FALSE(qr.insert_column(0, near, 1e-3));  // QR2 test: orthogonal part < 1e-3 |v|
  CHECK(qr.cols() == 2);
  Eigen::MatrixXd ba(m, 2);
  ba << b, a;
  check_factorisation(qr, ba);
  CHECK(qr.insert_column(0, near));  // accepted without a limit
  CHECK(qr.cols() == 3);
}

TEST_CASE("IQN-ILS QR1 filter drops a duplicated column", "[coupling][acceleration][qr]") {
  // H(x) = A x + b; the columns of V are (A - I) dx. Steps dx = e0, e1, e1 + 1e-9 e2 make the
  // third column a near duplicate of the second.
  const int n = 5;
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = 0.1 * (i + 1) - 0.05 * j * j + (i == j ? 0.5 : 0.0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  const Eigen::VectorXd weights = Eigen::VectorXd::Constant(n, 0.5);
  auto run = [&](IqnIls::Filter filter, double eps) {
    IqnIls::Options o;
    o.filter = filter;
    o.filter_limit = 1e-3;
    IqnIls iqn(o);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n), next;
    std::vector<Eigen::VectorXd> steps = {
        Eigen::VectorXd::Unit(n, 0), Eigen::VectorXd::Unit(n, 1),
        Eigen::VectorXd::Unit(n, 1) + eps * Eigen::VectorXd::Unit(n, 2)};
    iqn.accelerate(x, a * x + b, weights, next);
    for (const auto& dx : steps) {
      x += dx;
      iqn.accelerate(x, a * x + b, weights, next);
      // the factorisation is that of D V
      const Eigen::MatrixXd dv = weights.asDiagonal() * iqn.v();
      REQUIRE(iqn.qr().cols() == iqn.v().cols());
      CHECK((iqn.qr().q() * iqn.qr().r() - dv).norm() <= 1e-12 * dv.norm());
    }
    return iqn;
  };
  SECTION("a near duplicate (1e-9 apart) is kept without a filter and dropped by QR1") {
    const IqnIls none = run(IqnIls::Filter::none, 1e-9);
    CHECK(none.columns() == 3);
    CHECK(none.filtered_columns() == 0);
    const IqnIls qr1 = run(IqnIls::Filter::qr1, 1e-9);
    CHECK(qr1.columns() == 2);
    CHECK(qr1.filtered_columns() == 1);
    // the older copy went (its R_ii became tiny once the new column was in front), the newest
    // column and the first one remain
    const Eigen::MatrixXd am = a - Eigen::MatrixXd::Identity(n, n);
    const Eigen::VectorXd dup =
        am * (Eigen::VectorXd::Unit(n, 1) + 1e-9 * Eigen::VectorXd::Unit(n, 2));
    CHECK((qr1.v().col(0) - dup).norm() <= 1e-12 * dup.norm());
    CHECK((qr1.v().col(1) - am.col(0)).norm() <= 1e-12 * am.col(0).norm());
    CHECK(qr1.qr_rebuilds() == 1);  // built once (first call), updated since
  }
  SECTION("an exact duplicate is never inserted") {
    const IqnIls qr1 = run(IqnIls::Filter::qr1, 0.0);
    CHECK(qr1.columns() == 2);
    CHECK(qr1.filtered_columns() == 1);
  }
}

TEST_CASE("IQN-ILS updates its QR across windows as a rebuild newest first would filter it",
          "[coupling][acceleration][qr]") {
  // Two fields whose scaling changes by different factors between windows force a rebuild; one
  // common factor only rescales R.
  const int n = 10;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = 0.9 * u(rng) / std::sqrt(double(n));
  for (const bool common : {true, false}) {
    IqnIls::Options o;
    o.reused_windows = 2;
    o.max_columns = 12;
    o.filter = IqnIls::Filter::qr2;
    o.filter_limit = 1e-2;
    IqnIls iqn(o);
    Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
    for (int window = 0; window < 6; ++window) {
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) b(i) = u(rng) + window;
      weights.head(n / 2) *= 0.7;
      weights.tail(n - n / 2) *= common ? 0.7 : 1.3;
      Eigen::VectorXd x = Eigen::VectorXd::Zero(n), next;
      for (int k = 0; k < 30; ++k) {
        const Eigen::VectorXd h = a * x + b;
        if ((h - x).norm() <= 1e-10 * h.norm()) break;
        iqn.accelerate(x, h, weights, next);
        x = next;
        const Eigen::MatrixXd dv = weights.asDiagonal() * iqn.v();
        REQUIRE(iqn.qr().cols() == iqn.v().cols());
        CHECK(iqn.v().cols() <= o.max_columns);
        if (dv.cols() == 0) continue;
        const Eigen::Index c = dv.cols();
        CHECK((iqn.qr().q().transpose() * iqn.qr().q() - Eigen::MatrixXd::Identity(c, c))
                  .lpNorm<Eigen::Infinity>() < 1e-12);
        CHECK((iqn.qr().q() * iqn.qr().r() - dv).norm() <= 1e-12 * dv.norm());
        // a rebuild newest column first with the QR2 test would keep every column
        QrFactorization fresh;
        fresh.reset(n);
        for (Eigen::Index j = 0; j < c; ++j) CHECK(fresh.append(dv.col(j), 0.99 * o.filter_limit));
      }
      iqn.window_converged(x, a * x + b, weights);
    }
    INFO("common factor " << common << ": rebuilds " << iqn.qr_rebuilds());
    if (common)
      CHECK(iqn.qr_rebuilds() == 1);
    else
      CHECK(iqn.qr_rebuilds() >= 5);
  }
}
