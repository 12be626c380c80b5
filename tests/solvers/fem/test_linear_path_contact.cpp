// Operator contributions (a rigid indenter's contact) on the linear path's static and Newmark
// analyses: K u plus the contact, solved by Newton (the operator's tangent is no longer constant),
// against the nonlinear path with the linear-elastic law, the series stiffness of a column and its
// penalty springs, central difference driven to its quasi-static limit, and the energy of an
// elastic block bouncing off a rigid plane under average-acceleration Newmark.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/indenter_contact.hpp"
#include "partita/fem/plane_shape.hpp"
#include "partita/fem/sphere_shape.hpp"
#include "partita/fem/structural_solver.hpp"
#include "partita/fem/velocity_table.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 70e9, kNu = 0.3, kRho = 2700;

IndenterContact& add_contact(StructuralSolver& s, const std::string& face, RigidIndenter indenter,
                             IndenterContactOptions options = {}) {
  auto c = std::make_unique<IndenterContact>("indenter", s.model(), face, std::move(indenter),
                                             options);
  IndenterContact& ref = *c;
  s.add_contribution(std::move(c));
  return ref;
}

// An elastic column side x side x height on rollers (zmin fixed in z, xmin in x, ymin in y).
Model column(double side, double height, int cells) {
  BoxSpec b;
  b.size = Vec3(side, side, height);
  b.cells = {cells, cells, 8};
  Model model(make_box_mesh(b), Material{kE, kNu, kRho});
  model.fix("zmin", {2});
  model.fix("xmin", {0});
  model.fix("ymin", {1});
  return model;
}

}  // namespace

// A frictionless flat punch driven by delta into the column: uniaxial stress in series with the
// penalty springs (sum k_n = f E A / h), F = delta / (H / (E A) + h / (f E A)), on the linear path
// (K u + contact, Newton) whichever integrator the solver was made for (the static solve of a
// central-difference solver included: it must see the contact too), and the support reaction
// equals the punch force.
TEST_CASE("linear path with contact, static: a flat punch on a column gives the series stiffness",
          "[fem][contact][linear-path]") {
  const double side = 0.02, height = 0.04, delta = 2e-5, factor = 10.0;
  SolverOptions o;
  o.integrator = GENERATE(Integrator::Newmark, Integrator::CentralDifference);
  INFO("central difference " << (o.integrator == Integrator::CentralDifference));
  if (o.integrator == Integrator::CentralDifference) o.mass = MassType::Lumped;
  StructuralSolver s(column(side, height, 4), o);
  auto plane = std::make_shared<PlaneShape>(Vec3(0, 0, height), Vec3(0, 0, -1));
  IndenterContact& c = add_contact(
      s, "zmax", RigidIndenter(plane, VelocityTable({{0.0, Vec3(0, 0, -delta)}})), {factor, 0.0, 1.0});
  s.step_static(1.0);
  const double area = side * side, h = height / 8;
  const double exact = delta / (height / (kE * area) + h / (factor * kE * area));
  CHECK(c.contact_force().z() == Approx(exact).epsilon(1e-9));
  CHECK(s.reaction("zmin").z() == Approx(c.contact_force().z()).epsilon(1e-9));
  CHECK(c.active_nodes() == 25);
  CHECK(s.newton_iterations() > 0);  // Newton on K u + contact, not the factorised K alone
  // the punch's work is the stored energy (elastic + penalty) of the one-step ramp
  CHECK(c.indenter().work() == Approx(0.5 * exact * delta).epsilon(1e-9));
  CHECK(s.strain_energy() == Approx(0.5 * exact * delta).epsilon(1e-9));
}

// A rigid sphere pressed into a block in static steps: the linear path (K u + contact) and the
// nonlinear path with the small-strain linear-elastic law (the same Hex8 modes, element by
// element) solve the same equations, so they carry the same force at every penetration, to the
// Newton tolerance.
TEST_CASE("linear path with contact, static: the nonlinear path's force-penetration curve",
          "[fem][contact][linear-path]") {
  const double size = 0.02, r = 0.01, depth = 4e-4;
  auto run = [&](bool nonlinear_path) {
    BoxSpec b;
    b.origin = Vec3(0, 0, -size);
    b.size = Vec3(size, size, size);
    b.cells = {6, 6, 6};
    Model model(make_box_mesh(b), Material{kE, kNu, kRho});
    model.fix("zmin", {0, 1, 2});
    model.fix("xmin", {0});
    model.fix("ymin", {1});
    SolverOptions o;
    o.nonlinear_path = nonlinear_path;
    o.newton.force_tolerance = 1e-10;
    StructuralSolver s(std::move(model), o);
    auto sphere = std::make_shared<SphereShape>(Vec3(0, 0, r), r);
    IndenterContact& c = add_contact(
        s, "zmax", RigidIndenter(sphere, VelocityTable({{0.0, Vec3(0, 0, -depth)}})), {10.0, 0.0, 1.0});
    std::vector<double> force;
    for (int k = 0; k < 4; ++k) {
      s.step_static(0.25);
      force.push_back(c.contact_force().z());
    }
    return force;
  };
  const auto linear = run(false), nonlinear = run(true);
  for (std::size_t k = 0; k < linear.size(); ++k) {
    INFO("step " << k << ": linear path " << linear[k] << " N, nonlinear path " << nonlinear[k]);
    CHECK(linear[k] > 0.0);
    CHECK(linear[k] == Approx(nonlinear[k]).epsilon(1e-7));
    if (k > 0) CHECK(linear[k] > linear[k - 1]);  // the force grows with the penetration
  }
}

// Central difference on the linear path with the same punch driven slowly (a ramp of 3 ms, a
// hundred times the column's first period, then held 1 ms) and mass-proportional damping of
// about half the critical on the column's first mode (alpha = 2e5 /s: every mode decays as
// exp(-alpha t / 2), the penalty springs' chatter too; with a tenth of it the nodes keep
// bouncing on the punch): its quasi-static limit is the static solve's force.
TEST_CASE("linear path with contact: central difference driven slowly reaches the static force",
          "[fem][contact][linear-path]") {
  const double side = 0.02, height = 0.04, delta = 2e-5, factor = 10.0, ramp = 3e-3, hold = 1e-3;
  SolverOptions so;
  StructuralSolver st(column(side, height, 2), so);
  auto plane = std::make_shared<PlaneShape>(Vec3(0, 0, height), Vec3(0, 0, -1));
  IndenterContact& cs = add_contact(
      st, "zmax", RigidIndenter(plane, VelocityTable({{0.0, Vec3(0, 0, -delta)}})), {factor, 0.0, 1.0});
  st.step_static(1.0);
  const double f_static = cs.contact_force().z();

  SolverOptions o;
  o.integrator = Integrator::CentralDifference;
  o.mass = MassType::Lumped;
  o.rayleigh_alpha = 2e5;  // zeta about 0.5 on the column's first mode
  StructuralSolver s(column(side, height, 2), o);
  const double v = delta / ramp;
  IndenterContact& c = add_contact(
      s, "zmax",
      RigidIndenter(plane, VelocityTable({{0.0, Vec3(0, 0, -v)}, {ramp, Vec3(0, 0, -v)},
                                          {ramp * (1 + 1e-9), Vec3::Zero()}})),
      {factor, 0.0, 1.0});
  const double dt = 0.9 * s.stable_time_step();
  while (s.time() < ramp + hold) s.step(dt);
  INFO("central difference " << c.contact_force().z() << " N, static " << f_static << " N");
  CHECK(std::abs(c.indenter().displacement().z() + delta) < 1e-3 * delta);
  CHECK(c.active_nodes() == 9);
  CHECK(c.contact_force().z() == Approx(f_static).epsilon(1e-6));
  CHECK(s.reaction("zmin").z() == Approx(f_static).epsilon(1e-6));
}

// An elastic block moving at v0 onto a fixed rigid plane (no supports, no gravity, no damping),
// Newmark with beta = 1/4, gamma = 1/2 on the linear path, Newton on K u + contact: the energy
// (kinetic + strain + penalty) stays that of the start within 1 % through the impact, and the
// block leaves the plane moving away from it at most of its speed (part of the energy stays in
// the block's vibration).
TEST_CASE("linear path with contact, Newmark: a block bouncing off a plane keeps its energy",
          "[fem][contact][linear-path]") {
  const double side = 0.02, v0 = 1.0, gap = 1e-6;
  BoxSpec b;
  b.origin = Vec3(0, 0, gap);
  b.size = Vec3(side, side, side);
  b.cells = {4, 4, 4};
  SolverOptions o;
  o.newmark_beta = 0.25;
  o.newmark_gamma = 0.5;
  StructuralSolver s(Model(make_box_mesh(b), Material{kE, kNu, kRho}), o);
  auto floor = std::make_shared<PlaneShape>(Vec3::Zero(), Vec3(0, 0, 1));
  IndenterContact& c = add_contact(s, "zmin", RigidIndenter(floor, VelocityTable({{0.0, Vec3::Zero()}})),
                                   {1.0, 0.0, 1.0});
  SolverState start = s.save_state();
  for (Eigen::Index i = 2; i < start.velocity.size(); i += 3) start.velocity[i] = -v0;
  start.acceleration_valid = false;
  s.restore_state(start);
  const double mass = kRho * side * side * side;
  const double e0 = 0.5 * mass * v0 * v0;
  // the mean of the nodes' z velocities (the block's motion as a whole, its sign)
  auto mean_vz = [&] {
    double p = 0.0;
    for (Eigen::Index i = 2; i < s.velocity().size(); i += 3) p += s.velocity()[i];
    return p / static_cast<double>(s.velocity().size() / 3);
  };
  // the contact lasts about 2 side / c (c = sqrt(E / rho), 16 us) and a bit for the springs
  const double dt = 2e-7;
  double max_e_error = 0.0;
  int steps_in_contact = 0;
  for (int k = 0; k < 400; ++k) {
    s.step(dt);
    if (c.active_nodes() > 0) ++steps_in_contact;
    max_e_error = std::max(max_e_error, std::abs(s.kinetic_energy() + s.strain_energy() - e0));
    if (steps_in_contact > 0 && c.active_nodes() == 0 && mean_vz() > 0.0) break;
  }
  WARN("block on a plane, Newmark: " << steps_in_contact << " steps in contact, max |dE| / E0 = "
                                     << max_e_error / e0 << ", mean velocity after / before "
                                     << mean_vz() / -v0);
  CHECK(steps_in_contact > 20);
  CHECK(c.active_nodes() == 0);
  CHECK(mean_vz() > 0.8 * v0);  // it bounced: moving away at most of its speed
  CHECK(max_e_error < 0.01 * e0);
}
