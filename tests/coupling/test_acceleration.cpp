// Accelerations on linear fixed-point problems H(x) = A x + b, where theory gives the rates.
#include <catch2/catch.hpp>

#include <random>

#include <Eigen/LU>

#include "partita/coupling/acceleration/aitken.hpp"
#include "partita/coupling/acceleration/constant_relaxation.hpp"
#include "partita/coupling/acceleration/iqn_ils.hpp"

using namespace partita::coupling;

TEST_CASE("IQN-ILS solves a linear fixed point of dimension n within n + 1 iterations",
          "[coupling][acceleration]") {
  const int n = 12;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = u(rng);
  a *= 1.5 / std::sqrt(double(n));  // spectral radius about 1.5: plain iteration diverges
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b(i) = u(rng);
  const Eigen::VectorXd exact = (Eigen::MatrixXd::Identity(n, n) - a).partialPivLu().solve(b);

  IqnIls::Options o;
  o.initial_relaxation = 0.1;
  o.reused_windows = 0;
  o.filter = IqnIls::Filter::qr2;
  o.filter_limit = 1e-12;
  IqnIls iqn(o);
  const Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), next;
  int iterations = 0;
  double error = 1.0;
  // iteration k evaluates H(x_k) once; after n + 1 of them the secant model is exact
  for (int k = 1; k <= n + 1; ++k) {
    const Eigen::VectorXd h = a * x + b;
    iqn.accelerate(x, h, weights, next);
    x = next;
    iterations = k;
    error = (x - exact).norm() / exact.norm();
  }
  INFO("relative error after " << iterations << " iterations: " << error);
  CHECK(error < 1e-9);
  CHECK(iqn.columns() == n);

  // and not much earlier: after n - 2 iterations the model cannot be exact yet
  IqnIls again(o);
  x.setZero();
  for (int k = 1; k <= n - 2; ++k) {
    again.accelerate(x, a * x + b, weights, next);
    x = next;
  }
  CHECK((x - exact).norm() / exact.norm() > 1e-6);
}

TEST_CASE("IQN-ILS reuses columns of past windows and the QR2 filter drops dependent columns",
          "[coupling][acceleration]") {
  // The same linear problem in every window: with reused columns the second window needs fewer
  // iterations than the first.
  const int n = 6;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    a(i, i) = 0.9 - 0.3 * i;
    if (i + 1 < n) a(i, i + 1) = 0.4;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  const Eigen::VectorXd exact = (Eigen::MatrixXd::Identity(n, n) - a).partialPivLu().solve(b);
  IqnIls::Options o;
  o.reused_windows = 4;
  IqnIls iqn(o);
  const Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  auto solve_window = [&] {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n), next;
    for (int k = 1; k <= 50; ++k) {
      const Eigen::VectorXd h = a * x + b;
      if ((h - x).norm() <= 1e-10 * h.norm()) {
        iqn.window_converged(x, h, w);
        return k;
      }
      iqn.accelerate(x, h, w, next);
      x = next;
    }
    return 51;
  };
  const int first = solve_window();
  const int second = solve_window();
  INFO("iterations: first window " << first << ", second " << second);
  CHECK(first <= n + 2);
  CHECK(second < first);
  CHECK(second <= 3);  // the model from window 1 is exact: one step, then the check
  CHECK(iqn.filtered_columns() >= 0);
}

TEST_CASE(
    "Constant relaxation contracts by |1 - omega (1 - lambda)| per iteration on a diagonal map",
    "[coupling][acceleration]") {
  const Eigen::Vector3d lambda(0.5, -0.8, 0.9);
  const Eigen::Vector3d b(1.0, 2.0, -1.0);
  const Eigen::Vector3d exact = b.cwiseQuotient(Eigen::Vector3d::Ones() - lambda);
  const double omega = 0.6;
  ConstantRelaxation relax(omega);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(3), next;
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd h = lambda.cwiseProduct(x) + b;
    relax.accelerate(x, h, Eigen::VectorXd::Ones(3), next);
    for (int i = 0; i < 3; ++i) {
      const double ratio = (next(i) - exact(i)) / (x(i) - exact(i));
      CHECK(ratio == Approx(1.0 - omega * (1.0 - lambda(i))).epsilon(1e-9));
    }
    x = next;
  }
}

TEST_CASE("Aitken relaxation finds the secant factor 1 / (1 - lambda) on a scalar linear map",
          "[coupling][acceleration]") {
  // H(x) = lambda x + b diverges without relaxation for lambda = -3.
  const double lambda = -3.0, b = 2.0, exact = b / (1.0 - lambda);
  Aitken aitken(0.5);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 10.0), next;
  const Eigen::VectorXd w = Eigen::VectorXd::Ones(1);
  aitken.accelerate(x, lambda * x.array() + b, w, next);
  CHECK(aitken.omega() == 0.5);
  x = next;
  aitken.accelerate(x, lambda * x.array() + b, w, next);
  CHECK(aitken.omega() == Approx(1.0 / (1.0 - lambda)).epsilon(1e-12));
  CHECK(next(0) == Approx(exact).epsilon(1e-12));
  // the next window starts from min(initial, |omega|)
  aitken.window_converged(next, next, w);
  aitken.accelerate(x, lambda * x.array() + b, w, next);
  CHECK(aitken.omega() == Approx(0.25).epsilon(1e-12));
}
