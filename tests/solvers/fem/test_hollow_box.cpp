// The closed hollow box of the box mesher (wall_thickness > 0): its surfaces close (the
// divergence theorem gives the solid's volume), the inner faces bound the cavity with normals
// into it, gravity on it weighs the walls' volume, and its thin walls do not lock (a hollow
// square tube as a cantilever follows beam theory).
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {
const std::vector<std::string> kSides = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

struct Surface {
  Vec3 area_normal = Vec3::Zero();  // integral of n dA [m^2]
  double area = 0.0;                // [m^2]
  double x_dot_n = 0.0;             // integral of x . n dA [m^3]
};

Surface integrate(const StructuralSolver& s, const std::string& face) {
  Surface r;
  for (const auto& q : s.face_quadrature_points(face)) {
    r.area_normal += q.weight * q.normal;
    r.area += q.weight;
    r.x_dot_n += q.weight * q.position.dot(q.normal);
  }
  return r;
}
}  // namespace

TEST_CASE("hollow box: outer and inner faces enclose the walls' volume", "[fem][hollow]") {
  const Vec3 o(0.01, -0.02, 0.005), size(0.05, 0.03, 0.04);
  const double t = 0.004;
  const Vec3 cavity = size - Vec3::Constant(2 * t);
  const double v_walls = size.prod() - cavity.prod();
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    INFO("element " << to_string(type));
    BoxSpec spec{o, size, {5, 3, 4}, type, t, 2};
    Model model(make_box_mesh(spec), Material{70e9, 0.3, 2700});
    model.fix("zmin");
    model.add_gravity(Vec3(0, 0, -9.81));
    StructuralSolver s(model);
    // Divergence theorem over the solid's whole boundary (outer faces with outward normals, the
    // inner faces with normals into the cavity, i.e. out of the solid): int n dA = 0 and
    // 1/3 int x . n dA = the volume of the walls.
    Vec3 closed = Vec3::Zero();
    double volume = 0.0;
    for (const auto& f : kSides) {
      const Surface r = integrate(s, f);
      closed += r.area_normal;
      volume += r.x_dot_n / 3.0;
    }
    const Surface inner = integrate(s, "inner");
    closed += inner.area_normal;
    volume += inner.x_dot_n / 3.0;
    CHECK(closed.norm() < 1e-12);
    CHECK(volume == Approx(v_walls).epsilon(1e-12));
    // the inner surface alone is closed and bounds the cavity: 1/3 int x . n dA = -V_cavity
    CHECK(inner.area_normal.norm() < 1e-12);
    CHECK(inner.x_dot_n / 3.0 == Approx(-cavity.prod()).epsilon(1e-12));
    CHECK(inner.area ==
          Approx(2 * (cavity.x() * cavity.y() + cavity.y() * cavity.z() + cavity.z() * cavity.x()))
              .epsilon(1e-12));
    // each inner side: its area, normal into the cavity, at its plane
    for (int side = 0; side < 6; ++side) {
      const int d = side / 2;
      const double sign = side % 2 == 0 ? 1.0 : -1.0;  // inner_xmin faces +x (into the cavity)
      const Surface r = integrate(s, "inner_" + kSides[static_cast<std::size_t>(side)]);
      const double a = cavity.prod() / cavity[d];
      CHECK(r.area == Approx(a).epsilon(1e-12));
      CHECK(r.area_normal[d] == Approx(sign * a).epsilon(1e-12));
      const double plane = side % 2 == 0 ? o[d] + t : o[d] + size[d] - t;
      for (const auto& q :
           s.face_quadrature_points("inner_" + kSides[static_cast<std::size_t>(side)]))
        CHECK(q.position[d] == Approx(plane).epsilon(1e-12));
    }
    // the outer faces are those of the solid box: area of each side
    for (int side = 0; side < 6; ++side) {
      const int d = side / 2;
      CHECK(integrate(s, kSides[static_cast<std::size_t>(side)]).area ==
            Approx(size.prod() / size[d]).epsilon(1e-12));
    }
    // gravity weighs the walls only: rho V g
    CHECK(s.total_external_force().z() == Approx(-2700 * v_walls * 9.81).epsilon(1e-12));
    // node sets: inner nodes lie on the cavity surface, outer sets on their planes
    const Mesh& mesh = s.mesh();
    for (std::size_t n : mesh.node_set("inner")) {
      const Vec3 x = mesh.node(n) - o;
      bool on = false;
      for (int d = 0; d < 3; ++d)
        on = on || std::abs(x[d] - t) < 1e-12 || std::abs(x[d] - (size[d] - t)) < 1e-12;
      CHECK(on);
    }
    for (std::size_t n : mesh.node_set("xmax")) CHECK(mesh.node(n).x() == o.x() + size.x());
  }
}

// A closed thin-walled square tube (b = 0.1 m, t = 0.01 m, L = 2 m, nu = 0) clamped at one end,
// a shear load P on the other: Timoshenko beam deflection P L^3 / (3 E I) + P L / (k G A), with
// I = (b^4 - (b - 2t)^4) / 12, A = b^2 - (b - 2t)^2, k ~ 0.44 (thin square tube; the shear part
// is 0.5 % of the total). One Hex8 (incompatible modes) or Hex20 through the wall: within 3 %.
TEST_CASE("hollow box: a thin-walled tube cantilever does not lock", "[fem][hollow][slow]") {
  const double L = 2.0, b = 0.1, t = 0.01, E = 200e9, P = 1000.0;
  const double I = (std::pow(b, 4) - std::pow(b - 2 * t, 4)) / 12.0;
  const double A = b * b - (b - 2 * t) * (b - 2 * t);
  const double expected = P * L * L * L / (3 * E * I) + P * L / (0.44 * (E / 2) * A);
  for (auto type : {ElementType::Hex8, ElementType::Hex20}) {
    INFO("element " << to_string(type));
    BoxSpec spec{Vec3::Zero(), Vec3(L, b, b), {40, 4, 4}, type, t, 1};
    Model model(make_box_mesh(spec), Material{E, 0.0, 7800});
    model.fix("xmin");
    model.add_traction("xmax", Vec3(0, 0, P / (b * b)));
    StructuralSolver s(model);
    s.solve_static();
    const auto& tip = s.mesh().node_set("xmax");
    const MatrixX3 u = s.displacements(tip);
    const double w = u.col(2).mean();
    INFO("tip deflection " << w << " m, beam theory " << expected << " m");
    CHECK(w == Approx(expected).epsilon(0.03));
  }
}

TEST_CASE("hollow box: a wall thickness out of range is an error", "[fem][hollow]") {
  BoxSpec spec{Vec3::Zero(), Vec3(0.04, 0.02, 0.03), {2, 2, 2}, ElementType::Hex8, 0.01, 1};
  CHECK_THROWS_AS(make_box_mesh(spec), Error);  // 2 t = the smallest edge: no cavity
  spec.wall_thickness = -0.001;
  CHECK_THROWS_AS(make_box_mesh(spec), Error);
  spec.wall_thickness = 0.002;
  spec.wall_cells = 0;
  CHECK_THROWS_AS(make_box_mesh(spec), Error);
  spec.wall_cells = 1;
  CHECK_NOTHROW(make_box_mesh(spec));
}
