// Surface loads: quadrature points of named faces, tractions given at those points (the
// coupling input of seed 000), nodal forces, the coupling face mesh.
#include <catch2/catch.hpp>

#include "fem_test_helpers.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {
Mesh distorted_box(ElementType type) {
  BoxSpec spec{Vec3(0.0, 0.0, 0.0), Vec3(0.02, 0.03, 0.004), {3, 4, 2}, type};
  Mesh mesh = make_box_mesh(spec);
  // bend the top surface a little so that normals vary: z += 0.1 mm sin(...)
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    Vec3 x = mesh.node(i);
    x[2] += 1e-4 * (x[2] / 0.004) * std::sin(100 * x[0]) * std::cos(60 * x[1]);
    mesh.set_node(i, x);
  }
  return mesh;
}
}  // namespace

TEST_CASE("fem face quadrature points integrate area and normals", "[fem][surface]") {
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    Model model(make_box_mesh({Vec3(1, 2, 3), Vec3(0.5, 0.25, 0.2), {3, 2, 2}, type}));
    model.fix("xmin");
    StructuralSolver s(model);
    const std::vector<std::pair<std::string, Vec3>> faces = {
        {"xmin", Vec3(-0.05, 0, 0)}, {"xmax", Vec3(0.05, 0, 0)},   {"ymin", Vec3(0, -0.1, 0)},
        {"ymax", Vec3(0, 0.1, 0)},   {"zmin", Vec3(0, 0, -0.125)}, {"zmax", Vec3(0, 0, 0.125)}};
    for (const auto& [face, area_normal] : faces) {
      Vec3 sum = Vec3::Zero();
      Vec3 centroid = Vec3::Zero();
      double area = 0.0;
      for (const auto& q : s.face_quadrature_points(face)) {
        sum += q.weight * q.normal;
        area += q.weight;
        centroid += q.weight * q.position;
      }
      INFO(to_string(type) << " face " << face);
      CHECK((sum - area_normal).norm() < 1e-14);  // outward, and the right area
      CHECK(area == Approx(area_normal.norm()).epsilon(1e-13));
      // the triangulated coupling mesh has the same area
      const FaceMesh fm = s.face_mesh(face);
      double tri_area = 0.0;
      for (const auto& t : fm.triangles) {
        const Vec3 a = fm.positions.row(t[0]), b = fm.positions.row(t[1]),
                   c = fm.positions.row(t[2]);
        const Vec3 n = (b - a).cross(c - a);
        tri_area += 0.5 * n.norm();
        CHECK(n.normalized().dot(area_normal.normalized()) > 1 - 1e-12);
      }
      CHECK(tri_area == Approx(area).epsilon(1e-12));
      CHECK(fm.nodes == s.mesh().face_nodes(face));
    }
  }
}

TEST_CASE("fem uniform traction at quadrature points equals the pressure load", "[fem][surface]") {
  const double p = 1.234e4;
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    Mesh mesh = distorted_box(type);
    Model with_pressure(mesh);
    with_pressure.fix("zmin");
    with_pressure.add_pressure("zmax", p);
    Model plain(mesh);
    plain.fix("zmin");
    StructuralSolver a(with_pressure), b(plain);
    const auto qps = b.face_quadrature_points("zmax");
    MatrixX3 t(static_cast<Eigen::Index>(qps.size()), 3);
    for (std::size_t q = 0; q < qps.size(); ++q)
      t.row(static_cast<Eigen::Index>(q)) = -p * qps[q].normal.transpose();
    b.set_face_tractions_at_quadrature_points("zmax", t);
    b.solve_static();
    a.solve_static();
    INFO(to_string(type));
    const double scale = a.external_force().norm();
    CHECK((a.external_force() - b.external_force()).norm() < 1e-13 * scale);
    CHECK((a.displacement() - b.displacement()).norm() < 1e-12 * a.displacement().norm());
    // the sum of the nodal loads is the integral of the traction
    Vec3 integral = Vec3::Zero();
    for (std::size_t q = 0; q < qps.size(); ++q)
      integral += qps[q].weight * t.row(static_cast<Eigen::Index>(q)).transpose();
    CHECK((b.total_coupling_force() - integral).norm() < 1e-13 * integral.norm());
    // wrong number of rows is a clear error
    CHECK_THROWS_WITH(b.set_face_tractions_at_quadrature_points("zmax", MatrixX3::Zero(3, 3)),
                      Catch::Contains("quadrature points"));
    CHECK_THROWS_WITH(b.face_quadrature_points("top"), Catch::Contains("known faces"));
  }
}

TEST_CASE("fem nodal forces on face nodes keep their sum", "[fem][surface]") {
  Model model(make_box_mesh({Vec3::Zero(), Vec3(1, 1, 0.1), {4, 4, 1}, ElementType::Hex20}));
  model.fix("zmin");
  StructuralSolver s(model);
  const auto nodes = s.mesh().face_nodes("zmax");
  test::Lcg rng(3);
  MatrixX3 f(static_cast<Eigen::Index>(nodes.size()), 3);
  for (Eigen::Index i = 0; i < f.rows(); ++i) f.row(i) << rng.next(), rng.next(), rng.next();
  s.set_nodal_forces(nodes, f);
  const Vec3 sum = f.colwise().sum();
  CHECK((s.total_coupling_force() - sum).norm() < 1e-14);
  s.solve_static();
  CHECK((s.total_external_force() - sum).norm() < 1e-14);
  // equilibrium: the clamp takes it all
  CHECK((s.reaction("zmin") + sum).norm() < 1e-9 * sum.norm());
  CHECK_THROWS_AS(s.set_nodal_forces({999999}, MatrixX3::Zero(1, 3)), Error);
  CHECK_THROWS_AS(s.set_nodal_forces(nodes, MatrixX3::Zero(1, 3)), Error);
  s.clear_coupling_loads();
  CHECK(s.total_coupling_force().norm() == 0.0);
}
