// Static validation: slender cantilever against beam theory, the seed plate's support
// reactions, Lame's thick-walled cylinder.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "fem_test_helpers.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

// Cantilever L x h x h clamped at x = 0, tip load P (-z) as a uniform traction on x = L.
struct Cantilever {
  double length = 1.0, height = 0.05, load = 100.0;
  Material material{210e9, 0.3, 7800};
  double inertia() const { return std::pow(height, 4) / 12.0; }
  double beam_deflection() const {  // P L^3 / (3 E I)
    return load * std::pow(length, 3) / (3.0 * material.youngs_modulus * inertia());
  }
  Model model(ElementType type, std::array<int, 3> cells,
              Hex8Formulation f = Hex8Formulation::IncompatibleModes) const {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(length, height, height), cells, type}), material);
    m.set_hex8_formulation(f);
    m.fix("xmin");
    m.add_traction("xmax", Vec3(0, 0, -load / (height * height)));
    return m;
  }
  // mean tip deflection (positive down)
  static double tip(const StructuralSolver& s) {
    double sum = 0.0;
    const auto& nodes = s.mesh().node_set("xmax");
    for (auto n : nodes) sum += s.displacement(n)[2];
    return -sum / static_cast<double>(nodes.size());
  }
};

double cantilever_ratio(ElementType type, std::array<int, 3> cells, Hex8Formulation f) {
  Cantilever c;
  StructuralSolver s(c.model(type, cells, f));
  s.solve_static();
  const double ratio = Cantilever::tip(s) / c.beam_deflection();
  // the clamp carries the load
  CHECK(s.reaction("xmin")[2] == Approx(c.load).epsilon(1e-9));
  return ratio;
}

}  // namespace

TEST_CASE("fem cantilever under tip load vs beam theory", "[fem][static][cantilever]") {
  SECTION("hex20 within 2 %") {
    const double r =
        cantilever_ratio(ElementType::Hex20, {20, 1, 1}, Hex8Formulation::IncompatibleModes);
    INFO("hex20 w/w_beam = " << r);
    CHECK(std::abs(r - 1.0) < 0.02);
  }
  SECTION("tet10 within 2 %") {
    const double r =
        cantilever_ratio(ElementType::Tet10, {20, 2, 2}, Hex8Formulation::IncompatibleModes);
    INFO("tet10 w/w_beam = " << r);
    CHECK(std::abs(r - 1.0) < 0.02);
  }
  SECTION("hex8 incompatible modes within 5 %, plain hex8 locks") {
    const double r =
        cantilever_ratio(ElementType::Hex8, {20, 1, 1}, Hex8Formulation::IncompatibleModes);
    const double full = cantilever_ratio(ElementType::Hex8, {20, 1, 1}, Hex8Formulation::Full);
    INFO("hex8 QM6 w/w_beam = " << r << ", full integration w/w_beam = " << full);
    CHECK(std::abs(r - 1.0) < 0.05);
    CHECK(full < 0.8);  // shear locking of plain trilinear bricks
  }
}

TEST_CASE("fem seed plate under 10 kPa: support reactions equal p A", "[fem][static][plate]") {
  // CalculiX deck gen_plate.py: lateral-face nodes fixed in x, y; four bottom corners in z.
  const double lx = 0.02, ly = 0.02, lz = 0.002, p = 10e3;
  for (auto type : {ElementType::Hex8, ElementType::Hex20}) {
    // the decks' 20 x 20 x 2 cells for Hex8; 10 x 10 x 1 Hex20 (same node count, keeps it fast)
    const std::array<int, 3> cells =
        type == ElementType::Hex8 ? std::array<int, 3>{20, 20, 2} : std::array<int, 3>{10, 10, 1};
    Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(lx, ly, lz), cells, type});
    test::add_union_set(mesh, "lateral", {"xmin", "xmax", "ymin", "ymax"});
    mesh.add_node_set_where("corners", [&](const Vec3& x) {
      const double tol = 1e-9;
      return std::abs(x[2]) < tol && (std::abs(x[0]) < tol || std::abs(x[0] - lx) < tol) &&
             (std::abs(x[1]) < tol || std::abs(x[1] - ly) < tol);
    });
    REQUIRE(mesh.node_set("corners").size() == 4);
    Model model(mesh, Material{250e9, 0.3, 7850});
    model.fix("lateral", {0, 1});
    model.fix("corners", {2});
    model.add_pressure("zmax", p);
    StructuralSolver s(model);
    s.solve_static();
    const Vec3 r = s.reaction("corners");
    INFO(to_string(type) << " corner reaction z = " << r[2] << " N");
    CHECK(std::abs(r[2] - p * lx * ly) / (p * lx * ly) < 1e-10);
    CHECK(std::abs(s.total_external_force()[2] + p * lx * ly) < 1e-12);
  }
}

TEST_CASE("fem thick-walled cylinder under internal pressure (Lame, plane strain)",
          "[fem][static][lame]") {
  const double a = 0.1, b = 0.2, t = 0.01, p = 100e6, e = 200e9, nu = 0.3;
  BoxSpec spec{Vec3(a, 0, 0), Vec3(b - a, std::numbers::pi / 2, t), {8, 12, 1}, ElementType::Hex20};
  Mesh mesh = make_box_mesh(spec);
  // map (r, theta, z) -> (r cos theta, r sin theta, z): a quarter ring, edge nodes on the arcs
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    const Vec3 q = mesh.node(i);
    mesh.set_node(i, Vec3(q[0] * std::cos(q[1]), q[0] * std::sin(q[1]), q[2]));
  }
  Model model(mesh, Material{e, nu, 7800});
  model.fix("ymin", {1});  // theta = 0: the plane y = 0
  model.fix("ymax", {0});  // theta = 90 deg: the plane x = 0
  model.fix("zmin", {2});  // plane strain
  model.fix("zmax", {2});
  model.add_pressure("xmin", p);  // inner wall
  StructuralSolver s(model);
  s.solve_static();
  // u(r) = (1+nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r)
  const double ua = (1 + nu) * p * a * a / (e * (b * b - a * a)) * ((1 - 2 * nu) * a + b * b / a);
  // sigma_theta(a) = p a^2/(b^2-a^2) (1 + b^2/a^2)
  const double st = p * a * a / (b * b - a * a) * (1 + b * b / (a * a));
  const MatrixX6 stress = s.nodal_stress();
  double worst_u = 0.0, worst_s = 0.0;
  for (auto n : s.mesh().node_set("xmin")) {
    const Vec3 x = s.mesh().node(n);
    const double th = std::atan2(x[1], x[0]);
    const Vec3 er(std::cos(th), std::sin(th), 0), et(-std::sin(th), std::cos(th), 0);
    worst_u = std::max(worst_u, std::abs(s.displacement(n).dot(er) / ua - 1));
    Mat3 sig;
    const auto v = stress.row(static_cast<Eigen::Index>(n));
    sig << v(0), v(3), v(5), v(3), v(1), v(4), v(5), v(4), v(2);
    worst_s = std::max(worst_s, std::abs(et.dot(sig * et) / st - 1));
  }
  INFO("inner wall: worst radial displacement error " << worst_u * 100 << " %, hoop stress "
                                                      << worst_s * 100 << " %");
  CHECK(worst_u < 0.02);
  CHECK(worst_s < 0.02);
}
