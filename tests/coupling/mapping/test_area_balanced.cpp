// area-balanced: consistent (constants exact) and integral-preserving between weighted point sets,
// on the seed's route: STL cell centres (weights = triangle areas) -> FE face quadrature points
// (weights = quadrature weights), non-matching and perturbed.

#include <catch2/catch.hpp>

#include <random>

#include "partita/coupling/mapping/area_balanced_mapper.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;

namespace {

// Triangle centroids of an n x n split square [0, L]^2 (weights: the triangle areas), interior
// grid nodes perturbed.
Mesh centres(int n, double L, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jit(-0.25, 0.25);
  std::vector<Eigen::Vector2d> p((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool inner = i > 0 && i < n && j > 0 && j < n;
      p[j * (n + 1) + i] = Eigen::Vector2d(L * (i + (inner ? jit(rng) : 0.0)) / n,
                                           L * (j + (inner ? jit(rng) : 0.0)) / n);
    }
  Mesh::Points c(2 * n * n, 3);
  Eigen::VectorXd a(2 * n * n);
  int k = 0;
  auto tri = [&](int i0, int i1, int i2) {
    const Eigen::Vector2d x0 = p[i0], x1 = p[i1], x2 = p[i2];
    c.row(k) << (x0 + x1 + x2).x() / 3, (x0 + x1 + x2).y() / 3, 0.0;
    a(k) = 0.5 * std::abs((x1 - x0).x() * (x2 - x0).y() - (x1 - x0).y() * (x2 - x0).x());
    ++k;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int q = j * (n + 1) + i;
      tri(q, q + 1, q + n + 2);
      tri(q, q + n + 2, q + n + 1);
    }
  Mesh m("plate_centres", c);
  m.set_weights(a);
  return m;
}

// 2 x 2 Gauss points of an m x m grid of squares on [0, L]^2 (weights: (h/2)^2 each).
Mesh quadrature(int m, double L) {
  const double h = L / m, g = h / (2.0 * std::sqrt(3.0));
  Mesh::Points q(4 * m * m, 3);
  int k = 0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
          q.row(k++) << (i + 0.5) * h + (a ? g : -g), (j + 0.5) * h + (b ? g : -g), 0.0;
  Mesh mesh("bottom_quadrature", q);
  mesh.set_weights(Eigen::VectorXd::Constant(4 * m * m, h * h / 4));
  return mesh;
}

}  // namespace

TEST_CASE("area-balanced: constants exact, integral of a spiky density preserved", "[mapping]") {
  const double L = 0.02;
  const Mesh src = centres(16, L, 5);
  const Mesh dst = quadrature(20, L);
  REQUIRE(src.weights().sum() == Approx(L * L).epsilon(1e-12));
  AreaBalancedMapper m(Constraint::consistent, 6);
  m.compute(src, dst);

  // a constant traction arrives unchanged at every quadrature point
  Eigen::MatrixXd t = Eigen::MatrixXd::Constant(src.size(), 3, 0.0);
  t.col(2).setConstant(-1.0e4);
  Eigen::MatrixXd out;
  m.map(t, out);
  CHECK((out.col(2).array() + 1.0e4).abs().maxCoeff() < 1e-8);

  // spiky: traction on 30 random cells only (as DEM contacts): sum_q w_q t_q = sum_i A_i t_i
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(src.size()) - 1);
  t.setZero();
  for (int k = 0; k < 30; ++k) t(pick(rng), 2) = -0.13 / src.weights()(0) * (1 + k % 3);
  m.map(t, out);
  const double sent = src.weights().dot(t.col(2));
  const double arrived = dst.weights().dot(out.col(2));
  CHECK(std::abs(arrived - sent) <= 1e-10 * std::abs(sent));
  // rows of the operator are convex weights: no negative traction from a positive one
  CHECK(out.col(2).maxCoeff() <= 0.0);
}

TEST_CASE("area-balanced: needs point weights on both meshes", "[mapping]") {
  Mesh::Points p(3, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  const Mesh plain("vertices", p);
  Mesh weighted("centres", p);
  weighted.set_weights(Eigen::Vector3d(1, 1, 1));
  AreaBalancedMapper m(Constraint::consistent, 2);
  CHECK_THROWS_WITH(m.compute(weighted, plain),
                    Catch::Contains("needs point weights") && Catch::Contains("'vertices'"));
}
