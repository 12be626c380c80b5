// Patch test: every element type reproduces a linear displacement field (and the constant
// stress it implies) on a distorted mesh when the field is prescribed on the boundary.
#include <catch2/catch.hpp>

#include "fem_test_helpers.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

// u(x) = u0 + G x
const Vec3 kU0(1e-4, -2e-4, 3e-4);
Mat3 gradient() {
  Mat3 g;
  g << 1e-3, 2e-4, -3e-4, -1e-4, -5e-4, 4e-4, 2.5e-4, 3e-4, 8e-4;
  return g;
}

MatrixX6 run_patch(ElementType type, Hex8Formulation formulation,
                   std::array<int, 3> cells = {3, 3, 3}) {
  BoxSpec spec;
  spec.size = Vec3(1.0, 0.8, 1.2);
  spec.cells = cells;
  spec.element = type;
  Mesh mesh = make_box_mesh(spec);
  test::distort_interior(mesh, spec, 0.25, 7);
  test::add_union_set(mesh, "boundary", {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"});
  Material mat{200e9, 0.3, 7800};
  Model model(mesh, mat);
  model.set_hex8_formulation(formulation);
  const Mat3 g = gradient();
  for (int c = 0; c < 3; ++c) {
    model.prescribe_field("boundary", c,
                          [g, c](const Vec3& x, double) { return kU0[c] + g.row(c).dot(x); });
  }
  StructuralSolver solver(model);
  solver.solve_static();
  double err = 0.0, umax = 0.0;
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    const Vec3 exact = kU0 + g * mesh.node(i);
    err = std::max(err, (solver.displacement(i) - exact).norm());
    umax = std::max(umax, exact.norm());
  }
  INFO(to_string(type) << " max displacement error / max |u| = " << err / umax);
  CHECK(err / umax < 1e-10);
  // constant stress sigma = D eps
  const Mat3 eps = 0.5 * (g + g.transpose());
  Voigt ev;
  ev << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(0, 1), 2 * eps(1, 2), 2 * eps(2, 0);
  const Voigt sigma = mat.elasticity_matrix() * ev;
  const MatrixX6 s = solver.nodal_stress();
  double serr = 0.0;
  for (Eigen::Index i = 0; i < s.rows(); ++i)
    serr = std::max(serr, (s.row(i).transpose() - sigma).norm());
  INFO("max stress error / |sigma| = " << serr / sigma.norm());
  CHECK(serr / sigma.norm() < 1e-8);
  return s;
}

}  // namespace

TEST_CASE("fem patch test: linear field on a distorted mesh", "[fem][patch]") {
  SECTION("hex8 incompatible modes") {
    run_patch(ElementType::Hex8, Hex8Formulation::IncompatibleModes);
  }
  SECTION("hex8 full integration") {
    run_patch(ElementType::Hex8, Hex8Formulation::Full);
  }
  SECTION("hex20") {
    run_patch(ElementType::Hex20, Hex8Formulation::IncompatibleModes);
  }
  SECTION("tet4") {
    run_patch(ElementType::Tet4, Hex8Formulation::IncompatibleModes);
  }
  SECTION("tet10") {
    run_patch(ElementType::Tet10, Hex8Formulation::IncompatibleModes);
  }
}

TEST_CASE("fem patch test: nodal stresses of a larger mesh on 1, 2 and 3 threads", "[fem][patch]") {
  // 16 x 16 x 16 = 4096 elements: threaded (from 4096 on), in four chunks of 1024
  const int before = test::threads_available();
  MatrixX6 one;
  for (int threads : {1, 2, 3}) {
    test::use_threads(threads);
    INFO(threads << " threads");
    const MatrixX6 s = run_patch(ElementType::Hex8, Hex8Formulation::IncompatibleModes, {16, 16, 16});
    if (threads == 1)
      one = s;
    else
      CHECK((s.array() == one.array()).all());  // the same sums in the same order
  }
  test::use_threads(before);
}

TEST_CASE("fem box mesher: sets, faces and volumes", "[fem][mesh]") {
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    BoxSpec spec{Vec3(0.1, 0.2, 0.3), Vec3(2.0, 1.0, 0.5), {4, 3, 2}, type};
    const Mesh mesh = make_box_mesh(spec);
    ElementIntegrator integ;
    double volume = 0.0;
    for (const auto& e : mesh.elements()) {
      ElementCoordinates x(node_count(e.type), 3);
      for (int a = 0; a < node_count(e.type); ++a) x.row(a) = mesh.node(e.nodes[a]).transpose();
      volume += integ.volume(e.type, x);
    }
    CHECK(volume == Approx(1.0).epsilon(1e-12));
    const int per_cell = (type == ElementType::Hex8 || type == ElementType::Hex20) ? 1 : 6;
    CHECK(mesh.num_elements() == static_cast<std::size_t>(24 * per_cell));
    for (const auto& face : {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}) {
      CHECK(mesh.has_face(face));
      CHECK(mesh.has_node_set(face));
      CHECK(mesh.face_nodes(face) == mesh.node_set(face));
    }
    CHECK_THROWS_AS(mesh.node_set("nope"), Error);
  }
}
