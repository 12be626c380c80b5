// IQN-IMVJ on linear fixed-point problems H(x) = M x + b: the secant equations, the nearest
// update, the exact inverse Jacobian once a window has spanned the space, and the restarts.
#include <catch2/catch.hpp>

#include <random>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/acceleration/iqn_imvj.hpp"

using namespace partita::coupling;

namespace {

Eigen::MatrixXd random_map(int n, unsigned seed, double radius) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m(i, j) = u(rng);
  return m * (radius / std::sqrt(double(n)));  // spectral radius about `radius`
}

Eigen::VectorXd random_vector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = u(rng);
  return v;
}

// One window from x = 0 until |H(x) - x| <= tol |H(x)|; returns the evaluations of H.
int solve_window(Acceleration& acc, const Eigen::MatrixXd& m, const Eigen::VectorXd& b,
                 const Eigen::VectorXd& weights, int max_iterations = 60) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size()), next;
  for (int k = 1; k <= max_iterations; ++k) {
    const Eigen::VectorXd h = m * x + b;
    if ((h - x).norm() <= 1e-10 * h.norm()) {
      acc.window_converged(x, h, weights);
      return k;
    }
    acc.accelerate(x, h, weights, next);
    x = next;
  }
  return max_iterations + 1;
}

IqnImvj::Options exact_options() {
  IqnImvj::Options o;
  o.initial_relaxation = 0.1;
  o.filter_limit = 1e-12;
  o.truncation = 1e-13;
  o.chunk_size = 1000;
  return o;
}

}  // namespace

TEST_CASE("IQN-IMVJ: with no Jacobian from past windows it steps as IQN-ILS",
          "[coupling][acceleration]") {
  const int n = 10;
  const Eigen::MatrixXd m = random_map(n, 3, 1.5);
  const Eigen::VectorXd b = random_vector(n, 4), weights = Eigen::VectorXd::Ones(n);
  IqnImvj::Options oi = exact_options();
  IqnIls::Options ol;
  ol.initial_relaxation = oi.initial_relaxation;
  ol.reused_windows = 0;
  ol.filter_limit = oi.filter_limit;
  IqnImvj imvj(oi);
  IqnIls ils(ol);
  Eigen::VectorXd x1 = Eigen::VectorXd::Zero(n), x2 = x1, n1, n2;
  for (int k = 1; k <= n - 1; ++k) {
    imvj.accelerate(x1, m * x1 + b, weights, n1);
    ils.accelerate(x2, m * x2 + b, weights, n2);
    x1 = n1, x2 = n2;
    INFO("iteration " << k);
    CHECK((x1 - x2).norm() <= 1e-10 * x2.norm());
  }
}

TEST_CASE("IQN-IMVJ: a window that spans the space leaves the exact inverse Jacobian",
          "[coupling][acceleration]") {
  // r(x) = (M - I) x + b, H(x) = M x + b: dH = M (M - I)^{-1} dr. Once the window's secants span
  // R^n the multi-secant J equals it, and the next window (another b) is solved by one step.
  const int n = 8;
  const Eigen::MatrixXd m = random_map(n, 11, 1.4);
  const Eigen::MatrixXd id = Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd j_exact = m * (m - id).inverse();
  const Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
  IqnImvj imvj(exact_options());
  const int first = solve_window(imvj, m, random_vector(n, 12), weights);
  const Eigen::VectorXd y = random_vector(n, 13);
  const double j_error =
      (imvj.apply_previous_jacobian(y) - j_exact * y).norm() / (j_exact * y).norm();
  const int second = solve_window(imvj, m, random_vector(n, 14), weights);
  INFO("first window " << first << " evaluations, second " << second << "; |J - J_exact| "
                       << j_error);
  CHECK(first <= n + 2);
  CHECK(j_error < 1e-8);
  CHECK(second == 2);  // the exact step, then the evaluation that confirms it
}

TEST_CASE("IQN-IMVJ: J V = W after each window, and J is unchanged off the secants",
          "[coupling][acceleration]") {
  // Weighted (D = diag(weights)): Z = (V^T D^2 V)^{-1} V^T D^2, so J_new y = J_prev y for every
  // y with V^T D^2 y = 0. A window stopped after 4 evaluations gives 3 secants.
  const int n = 12;
  const Eigen::MatrixXd m = random_map(n, 21, 0.8);
  Eigen::VectorXd weights(n);
  for (int i = 0; i < n; ++i) weights(i) = i < n / 2 ? 1.0 : 30.0;
  IqnImvj imvj(exact_options());
  for (int window = 0; window < 3; ++window) {
    const Eigen::VectorXd b = random_vector(n, 30 + window);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n), next;
    Eigen::MatrixXd xs(n, 4), hs(n, 4);
    for (int k = 0; k < 4; ++k) {
      xs.col(k) = x;
      hs.col(k) = m * x + b;
      if (k < 3) imvj.accelerate(x, hs.col(k), weights, next), x = next;
    }
    // secants of this window: V = differences of r = H - x, W = differences of H
    Eigen::MatrixXd v(n, 3), w(n, 3);
    for (int k = 0; k < 3; ++k) {
      v.col(k) = (hs.col(k + 1) - xs.col(k + 1)) - (hs.col(k) - xs.col(k));
      w.col(k) = hs.col(k + 1) - hs.col(k);
    }
    // a probe D^2-orthogonal to V keeps its image
    const Eigen::MatrixXd d2v = weights.cwiseAbs2().asDiagonal() * v;
    Eigen::VectorXd off = random_vector(n, 40 + window);
    off -= v * (d2v.transpose() * v).ldlt().solve(d2v.transpose() * off);
    const Eigen::VectorXd before = imvj.apply_previous_jacobian(off);
    imvj.window_converged(xs.col(3), hs.col(3), weights);
    Eigen::MatrixXd jv(n, 3);
    for (int k = 0; k < 3; ++k) jv.col(k) = imvj.apply_previous_jacobian(v.col(k));
    const Eigen::VectorXd after = imvj.apply_previous_jacobian(off);
    INFO("window " << window << ": |J V - W| / |W| " << (jv - w).norm() / w.norm()
                   << ", image of the orthogonal probe moved by " << (after - before).norm());
    CHECK((jv - w).norm() <= 1e-9 * w.norm());
    CHECK((after - before).norm() <= 1e-9 * (1.0 + before.norm()) * off.norm());
    CHECK(imvj.jacobian_terms() == 3 * (window + 1));
  }
}

TEST_CASE("IQN-IMVJ restarts: svd keeps the Jacobian in fewer terms, zero drops it",
          "[coupling][acceleration]") {
  const int n = 6;
  const Eigen::MatrixXd m = random_map(n, 51, 1.3);
  const Eigen::MatrixXd j_exact = m * (m - Eigen::MatrixXd::Identity(n, n)).inverse();
  const Eigen::VectorXd weights = Eigen::VectorXd::Ones(n), y = random_vector(n, 52);
  IqnImvj::Options o = exact_options();
  o.chunk_size = 3;
  SECTION("svd") {
    // three windows add about 3 n terms; the rank of J is n, so the SVD keeps n of them
    IqnImvj imvj(o);
    for (int w = 0; w < 3; ++w) solve_window(imvj, m, random_vector(n, 60 + w), weights);
    CHECK(imvj.restarts() == 1);
    CHECK(imvj.jacobian_terms() == n);
    const double error =
        (imvj.apply_previous_jacobian(y) - j_exact * y).norm() / (j_exact * y).norm();
    INFO("|J - J_exact| after the restart " << error);
    CHECK(error < 1e-8);
    CHECK(solve_window(imvj, m, random_vector(n, 70), weights) == 2);
  }
  SECTION("zero") {
    o.restart = IqnImvj::Restart::zero;
    IqnImvj imvj(o);
    for (int w = 0; w < 3; ++w) solve_window(imvj, m, random_vector(n, 60 + w), weights);
    CHECK(imvj.restarts() == 1);
    CHECK(imvj.jacobian_terms() == 0);
    CHECK(solve_window(imvj, m, random_vector(n, 70), weights) > 2);
  }
}

TEST_CASE("IQN-IMVJ rejects bad options", "[coupling][acceleration]") {
  IqnImvj::Options o;
  o.initial_relaxation = 0.0;
  CHECK_THROWS_WITH(IqnImvj(o), Catch::Contains("0 < omega <= 1"));
  o = IqnImvj::Options{};
  o.chunk_size = 0;
  CHECK_THROWS_WITH(IqnImvj(o), Catch::Contains("chunk_size >= 1"));
  o = IqnImvj::Options{};
  o.truncation = 1.0;
  CHECK_THROWS_WITH(IqnImvj(o), Catch::Contains("truncation"));
}
