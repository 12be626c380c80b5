// Rigid indenters in contact with FE surfaces: the shapes' signed distances, the
// driven motion's exact integral, Hertz's sphere on an elastic block, a flat punch's reaction, a
// free mass dropped on a free block (momentum and energy), friction's dissipation and restart.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <numbers>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/capsule_shape.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/indenter_contact.hpp"
#include "partita/fem/plane_shape.hpp"
#include "partita/fem/sphere_shape.hpp"
#include "partita/fem/structural_solver.hpp"
#include "partita/fem/triangulated_shape.hpp"
#include "partita/fem/velocity_table.hpp"

using namespace partita::fem;

namespace {

// An aluminium block 20 x 20 x 10 mm of 4 x 4 x 2 cells (the contribution-level tests).
Model small_block() {
  BoxSpec b;
  b.size = Vec3(0.02, 0.02, 0.01);
  b.cells = {4, 4, 2};
  return Model(make_box_mesh(b), Material{70e9, 0.3, 2700});
}

// Adds a contact to the solver and returns it (the solver owns it).
IndenterContact& add_contact(StructuralSolver& s, const std::string& face, RigidIndenter indenter,
                             IndenterContactOptions options = {}) {
  auto c = std::make_unique<IndenterContact>("indenter", s.model(), face, std::move(indenter), options);
  IndenterContact& ref = *c;
  s.add_contribution(std::move(c));
  return ref;
}

// The closed surface of the box [lo, hi] (12 triangles, counter-clockwise seen from outside).
TriangulatedShape box_surface(const Vec3& lo, const Vec3& hi, double search) {
  std::vector<Vec3> v;
  for (int k = 0; k < 8; ++k)
    v.emplace_back((k & 1) ? hi.x() : lo.x(), ((k >> 1) & 1) ? hi.y() : lo.y(),
                   ((k >> 2) & 1) ? hi.z() : lo.z());
  std::vector<std::array<int, 3>> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                       {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                       {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return TriangulatedShape(v, t, search);
}

// An elastic column side x side x height on rollers (zmin fixed in z, xmin in x, ymin in y),
// cells x cells x 8 Hex8, E = 70 GPa, on the nonlinear path (static and Newmark contact).
StructuralSolver column_on_rollers(double side, double height, int cells, double e) {
  BoxSpec b;
  b.size = Vec3(side, side, height);
  b.cells = {cells, cells, 8};
  Model model(make_box_mesh(b), Material{e, 0.3, 2700});
  model.fix("zmin", {2});
  model.fix("xmin", {0});
  model.fix("ymin", {1});
  SolverOptions o;
  o.nonlinear_path = true;
  return StructuralSolver(std::move(model), o);
}

}  // namespace

TEST_CASE("rigid shapes: signed distances and outward normals", "[fem][contact]") {
  const SphereShape sphere(Vec3(1, 2, 3), 0.5);
  auto s = sphere.distance(Vec3(1, 2, 3.2));
  CHECK(s.gap == Approx(-0.3));
  CHECK(s.normal.z() == Approx(1.0));
  const CapsuleShape capsule(Vec3::Zero(), Vec3(0, 0, 2), 2.0, 0.5);
  s = capsule.distance(Vec3(0.7, 0, 0.9));  // beside the cylinder
  CHECK(s.gap == Approx(0.2));
  CHECK(s.normal.x() == Approx(1.0));
  s = capsule.distance(Vec3(0, 0, 1.3));  // inside the cap at +a: 0.3 from its centre
  CHECK(s.gap == Approx(-0.2));
  CHECK(s.normal.z() == Approx(1.0));
  const PlaneShape plane(Vec3(0, 0, 1), Vec3(0, 0, -2));
  CHECK(plane.distance(Vec3(5, 5, 0.75)).gap == Approx(0.25));
  CHECK(plane.distance(Vec3(5, 5, 1.1)).gap == Approx(-0.1));
  // the triangulations are closed and outward: volume by the divergence theorem
  for (const RigidShape* shape : {static_cast<const RigidShape*>(&sphere),
                                  static_cast<const RigidShape*>(&capsule)}) {
    const auto tri = shape->triangulate();
    double volume = 0.0;
    for (const auto& t : tri.triangles)
      volume += tri.vertices[t[0]].dot(tri.vertices[t[1]].cross(tri.vertices[t[2]])) / 6.0;
    const double exact = shape == &sphere ? 4.0 / 3.0 * std::numbers::pi * 0.125
                                          : std::numbers::pi * 0.25 * 2.0 + 4.0 / 3.0 * std::numbers::pi * 0.125;
    CHECK(volume == Approx(exact).epsilon(0.05));  // inscribed polyhedra: a few % less
    CHECK(volume < exact);
  }
  CHECK_THROWS_WITH(SphereShape(Vec3::Zero(), -1.0), Catch::Contains("radius must be > 0"));
}

TEST_CASE("triangulated shape: a cube's signed distance, inside and out, by the grid",
          "[fem][contact]") {
  const TriangulatedShape cube = box_surface(Vec3::Zero(), Vec3::Ones(), 0.2);
  auto s = cube.distance(Vec3(0.5, 0.5, 0.9));  // inside, 0.1 below the top
  CHECK(s.gap == Approx(-0.1));
  CHECK(s.normal.z() == Approx(1.0));
  s = cube.distance(Vec3(1.05, 0.5, 0.5));  // outside, 0.05 beyond x = 1
  CHECK(s.gap == Approx(0.05));
  CHECK(s.normal.x() == Approx(1.0));
  s = cube.distance(Vec3(1.05, 1.05, 1.05));  // outside a corner (vertex pseudo-normal)
  CHECK(s.gap == Approx(0.05 * std::sqrt(3.0)));
  s = cube.distance(Vec3(0.95, 0.97, 0.5));  // inside near an edge (edge pseudo-normal)
  CHECK(s.gap == Approx(-0.03));
  CHECK(cube.distance(Vec3(0.5, 0.5, 0.5)).gap == Approx(0.2));  // deeper than the search
  CHECK(cube.distance(Vec3(3, 3, 3)).gap == Approx(0.2));
  // against the analytic distance of a box at scattered points within the search radius
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 x(-0.2 + 1.4 * ((i * 37) % 101) / 100.0, -0.2 + 1.4 * ((i * 53) % 97) / 96.0,
                 -0.2 + 1.4 * ((i * 71) % 89) / 88.0);
    const Vec3 q = (x - Vec3::Constant(0.5)).cwiseAbs() - Vec3::Constant(0.5);
    const double exact = q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    if (std::abs(exact) >= 0.19) continue;
    ++checked;
    REQUIRE(cube.distance(x).gap == Approx(exact).margin(1e-12));
  }
  CHECK(checked > 500);
  CHECK(cube.max_cell_triangles() < 12);  // the grid narrows the search
  // a finer surface: the sphere's 320 triangles; a query tests a few of them, and the signed
  // distance is the sphere's within the polyhedron's sagitta (up to about 0.016 R on the
  // icosphere's largest triangles; 0.02 R allowed)
  const SphereShape ball(Vec3(1, 2, 3), 1.0);
  const auto tri = ball.triangulate();
  const TriangulatedShape hull(tri.vertices, tri.triangles, 0.1);
  CHECK(hull.max_cell_triangles() < 32);
  for (int i = 0; i < 200; ++i) {
    const Vec3 dir = Vec3(std::sin(0.7 * i), std::cos(1.3 * i), std::sin(2.1 * i + 0.3)).normalized();
    const Vec3 x = ball.centre() + (1.0 + 0.05 * std::sin(0.37 * i)) * dir;
    REQUIRE(hull.distance(x).gap == Approx(ball.distance(x).gap).margin(0.02));
    REQUIRE(hull.distance(x).normal.dot(dir) > 0.9);
  }
  CHECK_THROWS_WITH(TriangulatedShape({Vec3::Zero()}, {{0, 0, 1}}, 0.1),
                    Catch::Contains("refers to vertex 1"));
}

TEST_CASE("velocity table: its displacement is the exact integral", "[fem][contact]") {
  const VelocityTable v({{0.0, Vec3(0, 0, 0)}, {1.0, Vec3(0, 0, -2)}, {3.0, Vec3(1, 0, -2)}});
  CHECK(v.velocity(0.5).z() == Approx(-1.0));
  CHECK(v.displacement(1.0).z() == Approx(-1.0));             // triangle: 1/2 1 2
  CHECK(v.displacement(3.0).z() == Approx(-5.0));             // + 2 x 2
  CHECK(v.displacement(4.0).z() == Approx(-7.0));             // held after the last row
  CHECK(v.displacement(3.0).x() == Approx(1.0));              // 1/2 2 1
  CHECK(v.displacement(2.0).x() == Approx(0.25));             // 1/2 1 0.5
  CHECK_THROWS_WITH(VelocityTable({{1.0, Vec3::Zero()}, {1.0, Vec3::Zero()}}),
                    Catch::Contains("times must increase"));
}

// A frictionless rigid flat punch (a plane) driven by delta into the top of an elastic column on
// rollers: uniaxial stress, and in series with it the penalty springs, sum k_n = f E A / h:
//   F = delta / (H / (E A) + h / (f E A)).
// The support reaction equals the force on the punch.
TEST_CASE("flat punch on a block: reaction equals the punch force, uniaxial stiffness (plane and STL-like surface)",
          "[fem][contact]") {
  const double e = 70e9, side = 0.02, height = 0.04, delta = 2e-5, factor = 10.0;
  StructuralSolver s = column_on_rollers(side, height, 4, e);
  // the punch's face at z = H, moving down at delta per second: a plane, or a closed
  // triangulated box wider than the block (its bottom face the punch's)
  std::shared_ptr<const RigidShape> punch;
  if (GENERATE(false, true)) {
    punch = std::make_shared<TriangulatedShape>(box_surface(
        Vec3(-side, -side, height), Vec3(2 * side, 2 * side, height + side), 10 * delta));
  } else {
    punch = std::make_shared<PlaneShape>(Vec3(0, 0, height), Vec3(0, 0, -1));
  }
  INFO("punch: " << punch->kind());
  IndenterContact& c = add_contact(s, "zmax", RigidIndenter(punch, VelocityTable({{0.0, Vec3(0, 0, -delta)}})),
                                   {factor, 0.0, 1.0});
  s.step_static(1.0);
  const double area = side * side, h = height / 8;
  const double exact = delta / (height / (e * area) + h / (factor * e * area));
  const Vec3 on_punch = c.contact_force();
  CHECK(on_punch.z() == Approx(exact).epsilon(1e-9));
  CHECK(s.reaction("zmin").z() == Approx(on_punch.z()).epsilon(1e-9));
  CHECK(std::abs(on_punch.x()) < 1e-9 * exact);
  CHECK(c.active_nodes() == 25);
  // the indenter's work equals the stored energy (elastic + penalty) in a static ramp of one step
  CHECK(c.indenter().work() == Approx(0.5 * exact * delta).epsilon(1e-9));
  CHECK(s.strain_energy() == Approx(0.5 * exact * delta).epsilon(1e-9));
}

// Hertz: a rigid sphere of radius R pressed by delta into an elastic half-space carries
//   F = 4/3 E* sqrt(R) delta^(3/2),  E* = E / (1 - nu^2)
// (Johnson, Contact Mechanics, 1985, eq. 4.23). Quarter model of a block 20 R wide and deep
// (its rigid base stiffens it by about 0.7 a / H: 0.5 % at delta = 0.02 R), graded from cells of
// R / 40 under the sphere; symmetry planes x = 0 and y = 0; penalty factor 100 (penetration
// about h / (100 a) of delta). Quasi-static: the sphere driven down, a static solve per point.
TEST_CASE("Hertz: a rigid sphere pressed into an elastic block", "[fem][contact][hertz]") {
  const double e = 1e9, nu = 0.3, r = 0.01, size = 20 * r;
  const int n = 22;
  BoxSpec b;
  b.origin = Vec3(0, 0, -size);
  b.size = Vec3(size, size, size);
  b.cells = {n, n, n};
  Mesh mesh = make_box_mesh(b);
  // cells of h0 = R / 40 up to 0.2 R, then growing geometrically to the block's size
  const double h0 = r / 40.0;
  const int fine = 8;
  double ratio = 1.1;
  auto reach = [&](double q) {
    return fine * h0 + h0 * q * (std::pow(q, n - fine) - 1.0) / (q - 1.0);
  };
  for (int it = 0; it < 200; ++it) ratio *= std::pow(size / reach(ratio), 0.02);
  auto grade = [&](double x) {  // x in [0, size] on the uniform grid -> graded
    const double s = x / size * n;
    const int i = static_cast<int>(std::floor(s + 1e-9));
    if (i <= fine) return s * h0;
    const double k = s - fine;
    return fine * h0 + h0 * ratio * (std::pow(ratio, k) - 1.0) / (ratio - 1.0);
  };
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    const Vec3 x = mesh.node(i);
    mesh.set_node(i, Vec3(grade(x.x()), grade(x.y()), -grade(-x.z())));
  }
  Model model(std::move(mesh), Material{e, nu, 1000});
  model.fix("zmin", {0, 1, 2});
  model.fix("xmin", {0});
  model.fix("ymin", {1});
  SolverOptions o;
  o.nonlinear_path = true;
  StructuralSolver s(std::move(model), o);
  // the sphere touching the surface at the origin, driven down at R per second
  auto sphere = std::make_shared<SphereShape>(Vec3(0, 0, r), r);
  IndenterContact& c = add_contact(s, "zmax", RigidIndenter(sphere, VelocityTable({{0.0, Vec3(0, 0, -r)}})),
                                   {100.0, 0.0, 1.0});
  const double e_star = e / (1 - nu * nu);
  double t = 0.0;
  for (double ratio_d : {0.005, 0.01, 0.015, 0.02}) {
    s.step_static(ratio_d - t);
    t = ratio_d;
    const double delta = -c.indenter().displacement().z();
    const double hertz = 4.0 / 3.0 * e_star * std::sqrt(r) * std::pow(delta, 1.5);
    const double f = 4.0 * c.contact_force().z();  // quarter model
    INFO("delta/R = " << ratio_d << ": F = " << f << " N, Hertz " << hertz << " N, ratio "
                      << f / hertz << ", nodes in contact " << c.active_nodes());
    WARN("delta/R = " << ratio_d << ": F/F_Hertz = " << f / hertz);
    CHECK(f == Approx(hertz).epsilon(0.03));
  }
}

// A free rigid sphere (mass m, velocity v0) meets a free elastic block (no supports, no gravity,
// no damping): central difference. The momentum of sphere + block is conserved (the contact
// forces on nodes and body are equal and opposite at the same instants), and so is the energy
// (kinetic of both + strain + penalty) to the integrator's accuracy.
TEST_CASE("free mass dropped on a free block: momentum and energy conserved", "[fem][contact][drop]") {
  const double e = 210e9, nu = 0.3, rho = 7850, side = 0.1, r = 0.05, m = 2.0, v0 = 2.0;
  BoxSpec b;
  b.size = Vec3(side, side, side);
  b.cells = {6, 6, 6};
  SolverOptions o;
  // the nonlinear path (EAS elements, a sum of contributions) or the linear path (K u plus the
  // contact: LinearContributionOperator)
  o.nonlinear_path = GENERATE(true, false);
  INFO("nonlinear path " << o.nonlinear_path);
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  StructuralSolver s(Model(make_box_mesh(b), Material{e, nu, rho}), o);
  const double dt_elements = s.stable_time_step();
  auto sphere = std::make_shared<SphereShape>(Vec3(0.5 * side, 0.5 * side, side + r + 1e-6), r);
  IndenterContact& c = add_contact(s, "zmax", RigidIndenter(sphere, m, Vec3(0, 0, -v0), Vec3::Zero()));
  const double dt = 0.9 * s.stable_time_step();
  CHECK(s.stable_time_step() < dt_elements);  // the penalty springs lower it
  // lumped mass of the uniform Hex8 grid: each element gives each of its nodes rho V_e / 8
  Eigen::VectorXd nodal_mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(s.mesh().num_nodes()));
  const double cell = std::pow(side / 6, 3);
  for (const auto& el : s.mesh().elements())
    for (auto nd : el.node_span()) nodal_mass[static_cast<Eigen::Index>(nd)] += rho * cell / 8;
  auto momentum = [&] {
    double p = m * c.indenter().velocity().z();
    for (Eigen::Index i = 0; i < nodal_mass.size(); ++i) p += nodal_mass[i] * s.velocity()[3 * i + 2];
    return p;
  };
  auto energy = [&] {
    return c.indenter().kinetic_energy() + s.kinetic_energy() + s.strain_energy();
  };
  const double p0 = momentum(), e0 = energy();
  CHECK(p0 == Approx(-m * v0));
  CHECK(e0 == Approx(0.5 * m * v0 * v0));
  double max_force = 0.0, max_p_error = 0.0, max_e_error = 0.0;
  SolverState mid;
  bool saved = false;
  int steps_in_contact = 0;
  for (int k = 0; k < 4000; ++k) {
    s.step(dt);
    max_force = std::max(max_force, c.contact_force().z());
    if (c.active_nodes() > 0) ++steps_in_contact;
    if (!saved && steps_in_contact == 10) {
      mid = s.save_state();
      saved = true;
    }
    max_p_error = std::max(max_p_error, std::abs(momentum() - p0));
    max_e_error = std::max(max_e_error, std::abs(energy() - e0));
    if (steps_in_contact > 0 && c.active_nodes() == 0 && c.indenter().velocity().z() > 0 &&
        k > 50 + steps_in_contact)
      break;
  }
  INFO("peak force " << max_force << " N, " << steps_in_contact << " steps in contact, rebound "
                     << c.indenter().velocity().z() << " m/s");
  WARN("drop: " << steps_in_contact << " steps in contact, rebound " << c.indenter().velocity().z()
                 << " m/s, max |dP| / (m v0) = " << max_p_error / (m * v0)
                 << ", max |dE| / E0 = " << max_e_error / e0);
  CHECK(steps_in_contact > 20);
  CHECK(c.indenter().velocity().z() > 0.0);  // it rebounds
  CHECK(max_p_error < 0.01 * m * v0);
  CHECK(max_e_error < 0.01 * e0);
  // the sphere's lost kinetic energy went into the block: its momentum, the same as lost
  const double block_p = momentum() - m * c.indenter().velocity().z();
  CHECK(block_p == Approx(-m * v0 - m * c.indenter().velocity().z()).epsilon(0.01));
  // the sphere's work on the structure equals what the sphere lost (to the integrator's accuracy)
  CHECK(c.indenter().work() ==
        Approx(0.5 * m * v0 * v0 - c.indenter().kinetic_energy()).epsilon(0.01));
  // restart mid-contact: restoring the state and stepping again gives the same bits
  const auto after = s.save_state();
  const Vec3 d_after = c.indenter().displacement(), v_after = c.indenter().velocity();
  s.restore_state(mid);
  while (s.time() < after.time - 0.5 * dt) s.step(dt);
  CHECK(s.displacement() == after.displacement);
  CHECK(c.indenter().displacement() == d_after);
  CHECK(c.indenter().velocity() == v_after);
}

// Friction: a block sliding under a driven plane that presses it and drags it sideways. The
// frictional force on the punch is mu times the normal force once it slips, and the dissipated
// work is that force times the slip.
TEST_CASE("friction: a punch pressed and dragged sideways slips at mu times the normal force",
          "[fem][contact][friction]") {
  const double e = 70e9, nu = 0.3, side = 0.02, height = 0.02, delta = 1e-5, slide = 1e-4, mu = 0.3;
  BoxSpec b;
  b.size = Vec3(side, side, height);
  b.cells = {4, 4, 4};
  Model model(make_box_mesh(b), Material{e, nu, 2700});
  model.fix("zmin", {0, 1, 2});
  SolverOptions o;
  o.nonlinear_path = true;
  StructuralSolver s(std::move(model), o);
  auto plane = std::make_shared<PlaneShape>(Vec3(0, 0, height), Vec3(0, 0, -1));
  // pressed down by delta in [0, 1], then dragged along x by `slide` in [1, 2]
  const VelocityTable path({{0.0, Vec3(0, 0, -delta)},
                            {1.0, Vec3(0, 0, -delta)},
                            {1.0 + 1e-9, Vec3(slide, 0, 0)},
                            {2.0, Vec3(slide, 0, 0)}});
  IndenterContact& c = add_contact(s, "zmax", RigidIndenter(plane, path), {10.0, mu, 1.0});
  s.step_static(1.0);
  const double normal = c.contact_force().z();
  CHECK(normal > 0.0);
  CHECK(std::abs(c.contact_force().x()) < 1e-9 * normal);
  // pressing alone: the surface spreads under the punch (Poisson), its edge nodes slip a little
  CHECK(c.dissipated_work() < 1e-2 * normal * delta);
  const int steps = 8;
  const double dx = slide / steps;
  double w2 = 0.0, d2 = 0.0;
  for (int k = 0; k < steps; ++k) {
    s.step_static(1.0 / steps);
    if (k == 1) {
      w2 = c.indenter().work();
      d2 = c.dissipated_work();
    }
  }
  const Vec3 f = c.contact_force();
  INFO("normal " << f.z() << " N, tangential " << f.x() << " N");
  // the block's surface drags the punch back: -x on the punch, mu times the normal force
  CHECK(-f.x() == Approx(mu * f.z()).epsilon(2e-3));
  // in steady slip every node slides with the punch: dissipated mu F_n dx per step, the work
  // the punch does
  const double slipping = (steps - 2) * dx * mu * f.z();
  CHECK(c.dissipated_work() - d2 == Approx(slipping).epsilon(2e-3));
  CHECK(c.indenter().work() - w2 == Approx(slipping).epsilon(2e-3));
  CHECK(s.reaction("zmin").x() == Approx(f.x()).epsilon(1e-6));
}

// The contact's tangent against central differences of its force: exact for a plane (normal
// penalty, and friction in stick: k_t (I - n n^T)); for a sphere the left-out curvature term
// k_n g dn/dx is of relative size |g| / R (2e-3 here), relative to the stiffest column.
TEST_CASE("indenter contact: tangent against finite differences", "[fem][contact]") {
  const Model model = small_block();
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  struct Case {
    std::shared_ptr<const RigidShape> shape;
    double mu, tolerance;
  };
  const double r = 0.05;
  for (const Case& c : {Case{std::make_shared<PlaneShape>(Vec3(0, 0, 0.01 - 1e-5), Vec3(0.1, 0.2, -1)), 0.0, 1e-6},
                        Case{std::make_shared<PlaneShape>(Vec3(0, 0, 0.01 - 1e-5), Vec3(0.1, 0.2, -1)), 0.5, 1e-6},
                        Case{std::make_shared<SphereShape>(Vec3(0.01, 0.01, 0.01 + r - 1e-4), r), 0.0, 1e-2}}) {
    IndenterContact contact("t", model, "zmax",
                            RigidIndenter(c.shape, VelocityTable({{0.0, Vec3(1e-6, 0, 0)}})),
                            {1.0, c.mu, 1.0});
    contact.set_time(1.0, 1.0);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
    for (Eigen::Index i = 0; i < n; ++i) u[i] = 1e-7 * std::sin(1.3 * static_cast<double>(i));
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    SparseMatrix k = assembler.make_matrix();
    contact.add(u, f, &k, assembler);
    REQUIRE(contact.active_nodes() > 0);
    const Eigen::MatrixXd kd(k);
    const double scale = kd.colwise().norm().maxCoeff();  // k_n of the stiffest node
    const double h = 1e-10;
    double worst = 0.0;
    for (auto node : contact.nodes()) {
      for (int comp = 0; comp < 3; ++comp) {
        const Eigen::Index j = 3 * static_cast<Eigen::Index>(node) + comp;
        Eigen::VectorXd up = u, um = u, fp = Eigen::VectorXd::Zero(n), fm = fp;
        up[j] += h;
        um[j] -= h;
        contact.add(up, fp, nullptr, assembler);
        contact.add(um, fm, nullptr, assembler);
        const Eigen::VectorXd column = (fp - fm) / (2 * h);
        worst = std::max(worst, (column - kd.col(j)).norm() / scale);
      }
    }
    INFO(c.shape->kind() << ", mu " << c.mu << ": worst relative column error " << worst);
    CHECK(worst < c.tolerance);
  }
}

// Newmark (implicit, Newton with the contact's tangent): the flat punch driven slowly (a ramp of
// T = 10 ms, long beside the column's period of about 30 us) carries the static force of the
// column and penalty springs in series within 1 %, and the energy the punch put in is the
// column's strain + kinetic + penalty energy within 1 %.
TEST_CASE("flat punch, Newmark: quasi-static force and energy", "[fem][contact]") {
  const double e = 70e9, side = 0.02, height = 0.04, delta = 2e-5, factor = 10.0, t = 0.01;
  StructuralSolver s = column_on_rollers(side, height, 2, e);
  auto plane = std::make_shared<PlaneShape>(Vec3(0, 0, height), Vec3(0, 0, -1));
  IndenterContact& c = add_contact(
      s, "zmax", RigidIndenter(plane, VelocityTable({{0.0, Vec3(0, 0, -delta / t)}, {t, Vec3(0, 0, -delta / t)}, {t * 1.0001, Vec3::Zero()}})),
      {factor, 0.0, 1.0});
  for (int k = 0; k < 200; ++k) s.step(t / 200);
  const double area = side * side, h = height / 8;
  const double exact = delta / (height / (e * area) + h / (factor * e * area));
  CHECK(c.contact_force().z() == Approx(exact).epsilon(0.01));
  CHECK(c.indenter().work() == Approx(s.strain_energy() + s.kinetic_energy()).epsilon(0.01));
}

// A plane at rest 10 um into small_block()'s whole top face (5 x 5 nodes).
RigidIndenter plane_into_top_face() {
  return RigidIndenter(std::make_shared<PlaneShape>(Vec3(0, 0, 0.01 - 1e-5), Vec3(0, 0, -1)),
                       VelocityTable({{0.0, Vec3::Zero()}}));
}

// Erosion takes nodes off the contact surface: a node whose elements have all eroded touches
// nothing (set_detached, wired to StructuralSolver::node_detached by the FEM adapter).
TEST_CASE("indenter contact: detached nodes take no contact force", "[fem][contact][rupture]") {
  const Model model = small_block();
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  IndenterContact contact("t", model, "zmax", plane_into_top_face(), {1.0, 0.0, 1.0});
  contact.set_time(1.0, 1.0);
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd f_all = Eigen::VectorXd::Zero(n);
  contact.add(u, f_all, nullptr, assembler);
  REQUIRE(contact.active_nodes() == 25);
  // the nodes with x > 0.012 (two columns of 5) gone: 15 left, the others' forces unchanged
  contact.set_detached([&](std::size_t node) { return model.mesh().node(node).x() > 0.012; });
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  contact.add(u, f, nullptr, assembler);
  CHECK(contact.active_nodes() == 15);
  for (std::size_t node = 0; node < model.mesh().num_nodes(); ++node) {
    const auto at = 3 * static_cast<Eigen::Index>(node);
    if (model.mesh().node(node).x() > 0.012)
      CHECK(f.segment<3>(at).norm() == 0.0);
    else
      CHECK(f.segment<3>(at) == f_all.segment<3>(at));
  }
}

// A node whose contact faces have all eroded while it still belongs to an element (a web's node
// on the struck face, held by the web) has no penalty stiffness left: it touches nothing, and its
// springs store nothing (with friction, 0 / 0 would read as a non-finite energy).
TEST_CASE("indenter contact: a node without a face left takes no force and stores no energy",
          "[fem][contact][rupture]") {
  const Model model = small_block();
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  IndenterContact contact("t", model, "zmax", plane_into_top_face(), {1.0, 0.3, 1.0});
  const Mesh& mesh = model.mesh();
  const auto centre = [&](std::size_t e) {
    Vec3 c = Vec3::Zero();
    for (const auto node : mesh.element(e).node_span()) c += mesh.node(node);
    return Vec3(c / static_cast<double>(mesh.element(e).node_span().size()));
  };
  // the top layer's last column of elements (x > 15 mm) eroded: the top face's nodes at x = 20 mm
  // have no face left, those at x = 15 mm keep half their faces
  contact.set_eroded([&](std::size_t e) { return centre(e).x() > 0.015 && centre(e).z() > 0.005; });
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  contact.add(u, f, nullptr, assembler);  // at the committed state: the stiffnesses follow erosion
  CHECK(contact.active_nodes() == 20);
  CHECK(std::isfinite(contact.stored_energy()));
  CHECK(contact.stored_energy() > 0.0);
  for (std::size_t node = 0; node < mesh.num_nodes(); ++node) {
    const auto at = 3 * static_cast<Eigen::Index>(node);
    if (mesh.node(node).x() > 0.0199 && mesh.node(node).z() > 0.0099)
      CHECK(f.segment<3>(at).norm() == 0.0);
    else if (mesh.node(node).z() > 0.0099)
      CHECK(f.segment<3>(at).norm() > 0.0);
  }
}

// Eroding contact: the faces between elements (Mesh::add_interior_faces()) in the contact
// touch only where the element across has eroded. A plane 5 mm into the block's top layer: with
// the top layer's last column (x > 15 mm) eroded, the top face leaves 20 of its 25 nodes in
// contact (as above), and the faces erosion exposed bring the 10 nodes of the bottom layer's top
// faces under the hole (x = 15 and 20 mm, z = 5 mm); nothing before any erosion.
TEST_CASE("indenter contact: the faces erosion exposes join the contact", "[fem][contact][rupture]") {
  BoxSpec b;
  b.size = Vec3(0.02, 0.02, 0.01);
  b.cells = {4, 4, 2};
  Mesh block = make_box_mesh(b);
  block.add_interior_faces("between");
  const Model model(block, Material{70e9, 0.3, 2700});
  const Mesh& mesh = model.mesh();
  const BlockAssembler assembler(mesh);
  const auto n = static_cast<Eigen::Index>(3 * mesh.num_nodes());
  const auto plane = [] {
    return RigidIndenter(std::make_shared<PlaneShape>(Vec3(0, 0, 0.005 - 1e-5), Vec3(0, 0, -1)),
                         VelocityTable({{0.0, Vec3::Zero()}}));
  };
  const auto centre = [&](std::size_t e) {
    Vec3 c = Vec3::Zero();
    for (const auto node : mesh.element(e).node_span()) c += mesh.node(node);
    return Vec3(c / static_cast<double>(mesh.element(e).node_span().size()));
  };
  const auto column = [&](std::size_t e) { return centre(e).x() > 0.015 && centre(e).z() > 0.005; };
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  IndenterContact eroding("t", model, std::vector<std::string>{"zmax", "between"}, plane(),
                          {1.0, 0.0, 1.0});
  IndenterContact top_only("t", model, std::vector<std::string>{"zmax"}, plane(), {1.0, 0.0, 1.0});
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  eroding.add(u, f, nullptr, assembler);
  CHECK(eroding.active_nodes() == 25);  // nothing eroded: the faces between elements touch nothing
  eroding.set_eroded([&](std::size_t e) { return column(e); });
  top_only.set_eroded([&](std::size_t e) { return column(e); });
  f.setZero();
  eroding.add(u, f, nullptr, assembler);
  CHECK(eroding.active_nodes() == 30);
  for (std::size_t node = 0; node < mesh.num_nodes(); ++node) {
    const Vec3& x = mesh.node(node);
    if (std::abs(x.z() - 0.005) < 1e-9 && x.x() > 0.0149)
      CHECK(f.segment<3>(3 * static_cast<Eigen::Index>(node)).z() != 0.0);
  }
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  top_only.add(u, g, nullptr, assembler);
  CHECK(top_only.active_nodes() == 20);
}

TEST_CASE("free indenter: an external force decelerates it as F/m, its work is the change of kinetic energy",
          "[fem][contact]") {
  // no contact: a constant force F on a body of mass m moving at v0; velocity Verlet integrates a
  // constant acceleration exactly: d(t) = v0 t + F t^2 / (2 m), and F . d = m/2 (v^2 - v0^2)
  const double m = 2.0, v0 = -2.0, f = 3.0, dt = 1e-3;
  RigidIndenter body(std::make_shared<SphereShape>(Vec3(0, 0, 10), 0.5), m, Vec3(0, 0, v0), Vec3::Zero());
  body.set_external_force(Vec3(0, 0, f));
  const int n = 500;
  for (int k = 1; k <= n; ++k) {
    body.move_to(k * dt);
    body.set_contact_force(Vec3::Zero());
    body.commit();
  }
  const double t = n * dt;
  CHECK(body.displacement().z() == Approx(v0 * t + f * t * t / (2 * m)).epsilon(1e-12));
  CHECK(body.velocity().z() == Approx(v0 + f / m * t).epsilon(1e-12));
  CHECK(body.external_work() == Approx(0.5 * m * (std::pow(v0 + f / m * t, 2) - v0 * v0)).epsilon(1e-10));
  CHECK(body.work() == 0.0);
  CHECK_THROWS_WITH(body.set_external_force(Vec3(0, 0, std::nan(""))), Catch::Contains("finite"));
  // the state round trip keeps the force and its work (a resumed run goes on the same)
  std::vector<double> state(RigidIndenter::kStateSize);
  body.write_state(state);
  RigidIndenter copy(std::make_shared<SphereShape>(Vec3(0, 0, 10), 0.5), m, Vec3::Zero(), Vec3::Zero());
  copy.read_state(state);
  CHECK(copy.external_force() == body.external_force());
  CHECK(copy.external_work() == body.external_work());
  copy.move_to(t + dt);
  body.move_to(t + dt);
  CHECK(copy.trial_displacement() == body.trial_displacement());
}

// The books of a driven body's work, node by node. A free elastic column of 4 Hex8 at
// rest (linear path: K u, whose trapezoidal work is exact; lumped mass m_i), struck by a rigid plane
// driven down at constant speed V: no other force. Velocity Verlet's identity gives the kinetic
// energy as the trapezoidal work of the forces plus dt^2/8 sum |F_i|^2 / m_i, so with the body's
// work W integrated exactly along its path (the penalty force k_n |g| acting where the gap g,
// linear over the step, is < 0) the residual
//   r = W - (E_kin + E_strain + E_springs - dt^2/8 sum |F_i|^2 / m_i)
// changes over a step by minus what the central difference gives the nodes beyond the exact
// work of the force on their own path: at a touch (g_0 >= 0 > g_1) 1/2 (1 - s) p_1 . du, at a
// release (g_0 < 0 <= g_1) 1/2 (1 - s) p_0 . du, s = |g_in| / (|g_0| + |g_1|) the part of the
// step in contact, and 0 in contact at both ends. The first touch finds the nodes at rest
// (du = 0): the plane's work is then exactly the springs' energy, 4 x 1/2 k_n g_1^2, where the
// trapezoid over the whole step booked 1/2 k_n |g_1| (g_0 + |g_1|) per node.
TEST_CASE("driven plane on a free block: its work closes the energy books at every step",
          "[fem][contact][books]") {
  const double a = 0.01, rho = 7850, v = 1.0;
  SolverOptions o;
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  // a column of 4 cubes: the contact lasts some 4 wave transits (tens of steps)
  const double height = 4 * a;
  StructuralSolver s(Model(make_box_mesh({Vec3::Zero(), Vec3(a, a, height), {1, 1, 4}, ElementType::Hex8}),
                           Material{210e9, 0.3, rho}),
                     o);
  const double dt_elements = s.stable_time_step();
  const double z0 = height + 3.37 * v * dt_elements;  // the plane's start: it touches within a step
  auto plane = std::make_shared<PlaneShape>(Vec3(0, 0, z0), Vec3(0, 0, -1));
  IndenterContact& c = add_contact(s, "zmax", RigidIndenter(plane, VelocityTable({{0.0, Vec3(0, 0, -v)}})),
                                   {1.0, 0.0, 1.0, /*path_work=*/true});
  const double dt = 0.9 * s.stable_time_step();
  // lumped mass: each cube gives each of its nodes rho a^3 / 8
  Eigen::VectorXd nodal_mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(s.mesh().num_nodes()));
  for (const auto& el : s.mesh().elements())
    for (auto nd : el.node_span()) nodal_mass[static_cast<Eigen::Index>(nd)] += rho * a * a * a / 8.0;
  const auto& top = c.nodes();
  REQUIRE(top.size() == 4);
  // the gap of a top node j: the plane's height minus the node's
  auto gap = [&](std::size_t j, double t) {
    return z0 - v * t - (height + s.displacement()[3 * static_cast<Eigen::Index>(top[j]) + 2]);
  };
  auto residual = [&] {
    double half_step = 0.0;  // dt^2/8 sum |F_i|^2 / m_i, F_i = m a_i
    for (Eigen::Index i = 0; i < s.acceleration().size(); ++i)
      half_step += 0.125 * dt * dt * nodal_mass[i / 3] * s.acceleration()[i] * s.acceleration()[i];
    return c.indenter().work() - (s.kinetic_energy() + s.strain_energy() - half_step);
  };
  double r = residual(), scale = 0.0, excess_sum = 0.0;
  CHECK(r == 0.0);
  int touches = 0, releases = 0, both = 0;
  bool first_touch_checked = false;
  for (int step = 0; step < 600; ++step) {
    std::vector<double> g0(4), z_before(4);
    for (std::size_t j = 0; j < 4; ++j) {
      g0[j] = gap(j, s.time());
      z_before[j] = s.displacement()[3 * static_cast<Eigen::Index>(top[j]) + 2];
    }
    s.step(dt);
    double excess = 0.0;  // what the integrator gave the top nodes beyond the exact work
    for (std::size_t j = 0; j < 4; ++j) {
      const double g1 = gap(j, s.time()), k = c.penalty_stiffness()[j];
      const double du = s.displacement()[3 * static_cast<Eigen::Index>(top[j]) + 2] - z_before[j];
      if (g0[j] >= 0.0 && g1 < 0.0) {  // touch: p_1 = -k |g_1| (down)
        ++touches;
        excess += 0.5 * (g0[j] / (g0[j] - g1)) * (k * g1) * du;
      } else if (g0[j] < 0.0 && g1 >= 0.0) {  // release
        ++releases;
        excess += 0.5 * (g1 / (g1 - g0[j])) * (k * g0[j]) * du;
      } else if (g0[j] < 0.0) {
        ++both;
      }
    }
    if (!first_touch_checked && c.active_nodes() > 0) {
      first_touch_checked = true;
      REQUIRE(c.active_nodes() == 4);
      const double g1 = gap(0, s.time()), g_before = g0[0];
      CHECK(g_before > 0.0);  // a touch within the step, not at its start
      const double springs = 4.0 * 0.5 * c.penalty_stiffness()[0] * g1 * g1;
      CHECK(c.indenter().work() == Approx(springs).epsilon(1e-12));
      CHECK(s.strain_energy() == Approx(springs).epsilon(1e-12));
      WARN("first touch: the plane's work " << c.indenter().work() << " J = the springs' "
           << springs << " J; the trapezoid would have booked "
           << springs * (g_before - g1) / -g1 << " J");
    }
    const double r1 = residual();
    scale = std::max({scale, std::abs(c.indenter().work()), s.kinetic_energy()});
    INFO("step " << step << ": residual " << r1 << ", the integrator's excess " << excess);
    CHECK(r1 - r == Approx(-excess).margin(1e-9 * scale));
    excess_sum += excess;
    r = r1;
  }
  WARN("touches " << touches << ", releases " << releases << ", node-steps in contact " << both
       << "; the plane's work " << c.indenter().work() << " J, the block's kinetic energy "
       << s.kinetic_energy() << " J; the integrator's excess at touches and releases "
       << excess_sum << " J");
  CHECK(touches >= 4);
  CHECK(releases >= 4);
  CHECK(both > 20);
  CHECK(c.active_nodes() == 0);
  // gone: the block moves down faster than the plane (about 2 V: the elastic rebound from a
  // body of infinite mass)
  double vz = 0.0;
  for (Eigen::Index i = 2; i < s.velocity().size(); i += 3)
    vz += nodal_mass[i / 3] * s.velocity()[i] / nodal_mass.sum();
  CHECK(vz < -v);
}

TEST_CASE("indenter contact on two faces: the union's force is the sum of the faces' contacts",
          "[fem][contact]") {
  // A sphere (R = 10 mm) pressed into the edge where the block's top (zmax) and side (xmax)
  // meet: it reaches nodes of the top alone, of the side alone, and of both (the edge). The
  // penalty force -k_n g n is linear in k_n, and the union's k_n of a node is the sum of its
  // faces' elements' stiffness: frictionless, the union's nodal forces are the sum of the two
  // single-face contacts' at every node, and its active nodes their union.
  const Model model = small_block();
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  const auto sphere = [] {
    return RigidIndenter(std::make_shared<SphereShape>(Vec3(0.024, 0.01, 0.014), 0.010),
                         VelocityTable({{0.0, Vec3::Zero()}}));
  };
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  const auto forces = [&](IndenterContact& c, std::size_t& active) {
    c.set_time(1.0, 1.0);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    c.add(u, f, nullptr, assembler);
    active = c.active_nodes();
    return f;
  };
  IndenterContact top("top", model, "zmax", sphere()), side("side", model, "xmax", sphere());
  IndenterContact both("both", model, std::vector<std::string>{"zmax", "xmax"}, sphere());
  std::size_t a_top = 0, a_side = 0, a_both = 0;
  const Eigen::VectorXd f_top = forces(top, a_top), f_side = forces(side, a_side);
  const Eigen::VectorXd f_both = forces(both, a_both);
  // nodes in contact: the edge's (y = 5, 10, 15 mm) on both faces, one more on each face alone
  std::size_t shared = 0;
  for (std::size_t node = 0; node < model.mesh().num_nodes(); ++node) {
    const auto at = 3 * static_cast<Eigen::Index>(node);
    if (f_top.segment<3>(at).norm() > 0.0 && f_side.segment<3>(at).norm() > 0.0) ++shared;
  }
  REQUIRE(shared >= 1);
  REQUIRE(a_top > shared);
  REQUIRE(a_side > shared);
  CHECK(a_both == a_top + a_side - shared);
  const double scale = f_both.cwiseAbs().maxCoeff();
  REQUIRE(scale > 0.0);
  CHECK((f_both - (f_top + f_side)).cwiseAbs().maxCoeff() <= 1e-12 * scale);
  CHECK((both.contact_force() - (top.contact_force() + side.contact_force())).norm() <=
        1e-12 * both.contact_force().norm());
  // a face named twice, an unknown one
  CHECK_THROWS_WITH(IndenterContact("t", model, std::vector<std::string>{"zmax", "zmax"}, sphere()),
                    Catch::Contains("'zmax' is named twice"));
  CHECK_THROWS_WITH(IndenterContact("t", model, std::vector<std::string>{"zmax", "top"}, sphere()),
                    Catch::Contains("top"));
}
