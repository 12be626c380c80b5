#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "partita/geometry/closest_point.hpp"

using partita::geometry::closest_point_on_triangle;
using partita::geometry::TriangleClosestPoint;

namespace {

// The right triangle a = 0, b = e_x, c = e_y in the plane z = 0, seen through a rigid motion
// (rotation and translation): the closest point of the moved triangle to the moved query is the
// moved closest point, with the same barycentric weights and feature.
struct Frame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return rotation * x + shift; }
};

struct Expected {
  const char* region;
  Eigen::Vector3d query;  // in the triangle's own frame
  Eigen::Vector3d point;
  std::array<double, 3> barycentric;
  TriangleClosestPoint::Feature feature;
  int local_index;
};

void check_regions(const Frame& f) {
  const Eigen::Vector3d a = f({0, 0, 0}), b = f({1, 0, 0}), c = f({0, 1, 0});
  using F = TriangleClosestPoint;
  // Each query lies in one Voronoi region of the triangle; its closest point by hand: the
  // vertex, the foot of the perpendicular on the edge, or the projection onto the plane.
  const Expected cases[] = {
      {"vertex a", {-1.0, -0.5, 0.5}, {0, 0, 0}, {1, 0, 0}, F::vertex, 0},
      {"vertex b", {2.0, -0.5, 0.3}, {1, 0, 0}, {0, 1, 0}, F::vertex, 1},
      {"vertex c", {-0.2, 2.0, -1.0}, {0, 1, 0}, {0, 0, 1}, F::vertex, 2},
      {"edge ab", {0.25, -1.0, 2.0}, {0.25, 0, 0}, {0.75, 0.25, 0}, F::edge, 0},
      {"edge bc", {1.0, 0.5, 0.5}, {0.75, 0.25, 0}, {0, 0.75, 0.25}, F::edge, 1},
      {"edge ca", {-1.0, 0.25, -3.0}, {0, 0.25, 0}, {0.75, 0, 0.25}, F::edge, 2},
      {"face, above", {0.25, 0.5, 0.75}, {0.25, 0.5, 0}, {0.25, 0.25, 0.5}, F::face, 0},
      {"face, below", {0.125, 0.125, -2.0}, {0.125, 0.125, 0}, {0.75, 0.125, 0.125}, F::face, 0},
      {"face, in the plane", {0.5, 0.25, 0.0}, {0.5, 0.25, 0}, {0.25, 0.5, 0.25}, F::face, 0},
  };
  for (const auto& e : cases) {
    INFO(e.region);
    const TriangleClosestPoint r = closest_point_on_triangle(f(e.query), a, b, c);
    CHECK(r.feature == e.feature);
    CHECK(r.local_index == e.local_index);
    for (int k = 0; k < 3; ++k) CHECK(r.barycentric[k] == Approx(e.barycentric[k]).margin(1e-14));
    CHECK((r.point - f(e.point)).norm() < 1e-14 * (1.0 + f.shift.norm()));
  }
}

}  // namespace

TEST_CASE("closest point on a triangle: each Voronoi region (vertices, edges, face)",
          "[interface][geometry]") {
  SECTION("the triangle's own frame") { check_regions(Frame{}); }
  SECTION("rotated and moved") {
    Frame f;
    f.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    f.shift = {0.3, -2.0, 5.0};
    check_regions(f);
  }
}

TEST_CASE("closest point on a triangle: no point of the triangle is closer, weights consistent",
          "[interface][geometry]") {
  // An obtuse, tilted triangle and random queries around it, against a dense sample of the
  // triangle (the minimum over the sample can only be farther than the true closest point).
  const Eigen::Vector3d a(0.1, 0.2, -0.3), b(2.0, 0.4, 0.5), c(-0.7, 1.1, 0.9);
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-2.0, 3.0);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d p(u(gen), u(gen), u(gen));
    const TriangleClosestPoint r = closest_point_on_triangle(p, a, b, c);
    const auto& l = r.barycentric;
    for (double lk : l) CHECK(lk >= 0.0);
    CHECK(l[0] + l[1] + l[2] == Approx(1.0).epsilon(1e-14));
    CHECK((l[0] * a + l[1] * b + l[2] * c - r.point).norm() < 1e-13);
    const double d = (p - r.point).norm();
    const int n = 60;
    double sample_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double s = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
        sample_min = std::min(sample_min, (p - (a + s * (b - a) + t * (c - a))).norm());
      }
    CHECK(d <= sample_min + 1e-12);
    // the sample's spacing bounds how much closer the true point can be
    CHECK(d >= sample_min - (b - a).norm() / n - (c - a).norm() / n);
    // on the face the offset is along the normal; on an edge or vertex it is not toward inside
    if (r.feature == TriangleClosestPoint::face) {
      const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
      CHECK((p - r.point).cross(normal).norm() < 1e-12 * (1.0 + d));
    }
  }
}
