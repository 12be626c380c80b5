#include <catch2/catch.hpp>

#include "partita/interface/error.hpp"
#include "partita/interface/mesh.hpp"

using partita::Mesh;

namespace {
// Unit cube [0,1]^3 as 12 outward-oriented triangles.
Mesh unit_cube(double a = 1.0) {
  Mesh::Points p(8, 3);
  for (int i = 0; i < 8; ++i) p.row(i) << a * (i & 1), a * ((i >> 1) & 1), a * ((i >> 2) & 1);
  Mesh::Triangles t(12, 3);
  t << 0, 2, 1, 1, 2, 3,  // z = 0, normal -z
      4, 5, 6, 5, 7, 6,   // z = a, +z
      0, 1, 4, 1, 5, 4,   // y = 0, -y
      2, 6, 3, 3, 6, 7,   // y = a, +y
      0, 4, 2, 2, 4, 6,   // x = 0, -x
      1, 3, 5, 3, 7, 5;   // x = a, +x
  return Mesh("cube", p, t);
}
}  // namespace

TEST_CASE("closed cube: areas sum to the surface, area-weighted normals cancel",
          "[interface][mesh]") {
  const double a = 0.02;
  const Mesh m = unit_cube(a);
  // Surface of a cube: 6 a^2.
  CHECK(m.total_area() == Approx(6 * a * a).epsilon(1e-14));
  // For a closed surface, sum of A_i n_i = 0 (divergence theorem applied to a constant field).
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  const auto areas = m.triangle_areas();
  const auto normals = m.triangle_normals();
  for (Eigen::Index t = 0; t < m.num_triangles(); ++t) s += areas(t) * normals.row(t).transpose();
  CHECK(s.norm() < 1e-18);
  // Outward normals: (centroid - cube centre) . n > 0 for every face.
  const auto c = m.triangle_centroids();
  const Eigen::RowVector3d centre(a / 2, a / 2, a / 2);
  for (Eigen::Index t = 0; t < m.num_triangles(); ++t)
    CHECK((c.row(t) - centre).dot(normals.row(t)) > 0);
  // Volume by the divergence theorem: V = 1/3 sum A_i (c_i . n_i) = a^3.
  double vol = 0;
  for (Eigen::Index t = 0; t < m.num_triangles(); ++t)
    vol += areas(t) * c.row(t).dot(normals.row(t)) / 3;
  CHECK(vol == Approx(a * a * a).epsilon(1e-12));
  const auto box = m.bounding_box();
  CHECK(box.min.norm() == 0.0);
  CHECK((box.max - Eigen::Vector3d(a, a, a)).norm() == 0.0);
}

TEST_CASE("mesh rejects bad triangles and coordinates", "[interface][mesh]") {
  Mesh::Points p(3, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  Mesh::Triangles t(1, 3);
  t << 0, 1, 3;
  CHECK_THROWS_WITH(Mesh("m", p, t),
                    Catch::Contains("refers to point 3") && Catch::Contains("allowed: 0..2"));
  p(1, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(Mesh("m", p), Catch::Contains("NaN"));
}
