// Mass scaling of central-difference analyses (SolverOptions::mass_scaling_time_step): the
// density factor of each element, the wave speed it leaves, the energy balance with the scaled
// mass, and a slowly loaded cantilever that reaches its static deflection in fewer steps.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "fem_test_helpers.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/element_size.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7800.0;

double dilatational_speed() { return test::dilatational_speed(kE, kNu, kRho); }

// the uniaxial rod of fem_test_helpers.hpp: each element's stable step is h / c_d for a >= h
Model rod(double length, int n, double a = 0.01) {
  return test::uniaxial_rod(length, n, a, Material{kE, kNu, kRho});
}

SolverOptions scaled(double target) {
  SolverOptions o;
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  o.mass_scaling_time_step = target;
  return o;
}

}  // namespace

TEST_CASE("mass scaling: the density factor is (target / dt_e)^2 on a uniform rod",
          "[fem][explicit][mass-scaling]") {
  // cube elements: with y and z fixed the axial mode is each element's highest (dt_e = h / c_d)
  const double length = 1.0, a = 0.02;
  const int n = 50;
  const double dt_e = (length / n) / dilatational_speed();
  const double mass = kRho * length * a * a;
  SECTION("target above the elements' step: every element scaled by 9") {
    StructuralSolver s(rod(length, n, a), scaled(3.0 * dt_e));
    for (std::size_t e = 0; e < s.mesh().num_elements(); ++e)
      CHECK(s.mass_scale_factor(e) == Approx(9.0).epsilon(1e-12));
    CHECK(s.mass_scaled_elements() == static_cast<std::size_t>(n));
    CHECK(s.physical_mass() == Approx(mass).epsilon(1e-12));
    CHECK(s.added_mass() == Approx(8.0 * mass).epsilon(1e-12));
    // the stable step is raised to the target exactly (the scaled masses in the bound)
    CHECK(s.stable_time_step() == Approx(3.0 * dt_e).epsilon(1e-12));
  }
  SECTION("target below the elements' step: nothing added") {
    StructuralSolver s(rod(length, n, a), scaled(0.5 * dt_e));
    CHECK(s.mass_scaled_elements() == 0);
    CHECK(s.added_mass() == 0.0);
    CHECK(s.stable_time_step() == Approx(dt_e).epsilon(1e-12));
  }
}

TEST_CASE("mass scaling: a bar's wave travels at c / sqrt(s)", "[fem][explicit][mass-scaling]") {
  const double length = 1.0;
  const int n = 200;
  const double c = dilatational_speed(), h = length / n;
  // target 2 h / c: s = 4, the wave at c / 2
  Model m = rod(length, n);
  m.add_pressure("xmin", 1e6);
  StructuralSolver s(std::move(m), scaled(2.0 * h / c));
  const double c_scaled = c / std::sqrt(4.0);
  const double dt = 0.9 * s.stable_time_step();
  // free far end: its velocity jumps to 2 v, v = p / (rho s c_scaled), when the front arrives
  const double v = 1e6 / (4.0 * kRho * c_scaled);
  const auto far = s.mesh().node_set("xmax");
  double arrival = -1.0;
  while (s.time() < 2.0 * length / c_scaled && arrival < 0.0) {
    s.step(dt);
    if (s.velocity()[3 * static_cast<Eigen::Index>(far[0])] > v) arrival = s.time();
  }
  REQUIRE(arrival > 0.0);
  INFO("arrival " << arrival << " s, L / c' = " << length / c_scaled << " s");
  CHECK(std::abs(arrival - length / c_scaled) <= h / c_scaled);
}

TEST_CASE("mass scaling: the energy balance closes with the scaled mass (J2 cantilever)",
          "[fem][explicit][mass-scaling]") {
  // a clamped J2 cantilever pushed past first yield by a smooth tip load and released; its
  // elements graded towards the root (x = L s^2), so a target 3 times the smallest element's
  // stable step scales the short elements and leaves the long ones
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(0.2, 0.02, 0.02), {10, 1, 2}, ElementType::Hex8});
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    Vec3 x = mesh.node(i);
    x.x() = 0.2 * (x.x() / 0.2) * (x.x() / 0.2);
    mesh.set_node(i, x);
  }
  Model m(std::move(mesh));
  m.set_material_law(std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(250e6, 0.0)));
  m.set_hex8_formulation(Hex8Formulation::Full);
  m.fix("xmin");
  const double period = 2e-3;
  m.add_traction("xmax", Vec3(0, 0, -8e6), [period](double t) {
    return t < period ? 0.5 * (1.0 - std::cos(2.0 * M_PI * t / period)) : 0.0;
  });
  const double dt_plain = StructuralSolver(m, scaled(0.0)).stable_time_step();
  StructuralSolver s(std::move(m), scaled(3.0 * dt_plain));
  REQUIRE(s.mass_scaled_elements() > 0);
  REQUIRE(s.mass_scaled_elements() < s.mesh().num_elements());
  const double dt = 0.9 * s.stable_time_step();
  while (s.time() < 1.5 * period) s.step(dt);
  INFO("plastic work " << s.plastic_work() << " J, external work " << s.external_work()
                       << " J, kinetic " << s.kinetic_energy() << " J, balance "
                       << s.energy_balance() << " J");
  REQUIRE(s.plastic_work() > 0.0);
  CHECK(std::abs(s.energy_balance()) < 2e-3 * s.external_work());
  // the kinetic energy is that of the scaled mass: HRZ lumping of a parallelepiped puts 1/8 of
  // s_e rho V_e on each of its nodes
  double by_hand = 0.0;
  Eigen::VectorXd nodal = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(s.mesh().num_nodes()));
  for (std::size_t e = 0; e < s.mesh().num_elements(); ++e) {
    const auto nodes = s.mesh().elements()[e].node_span();
    const Vec3 diagonal = s.mesh().node(nodes[6]) - s.mesh().node(nodes[0]);
    const double me = kRho * diagonal.prod() * s.mass_scale_factor(e) / 8.0;
    for (auto node : nodes) nodal[static_cast<Eigen::Index>(node)] += me;
  }
  for (std::size_t i = 0; i < s.mesh().num_nodes(); ++i)
    by_hand += 0.5 * nodal[static_cast<Eigen::Index>(i)] *
               s.velocity().segment<3>(3 * static_cast<Eigen::Index>(i)).squaredNorm();
  CHECK(s.kinetic_energy() == Approx(by_hand).epsilon(1e-10));
}

TEST_CASE("mass scaling: a slowly loaded cantilever reaches its static deflection",
          "[fem][explicit][mass-scaling]") {
  // steel cantilever L = 0.1 m, 5 x 5 mm, 20 Hex8 (one through the depth), tip load P ramped
  // smoothly over 40 ms and held 10 ms; its first period is 2.4 ms, the elements' stable step
  // ~0.5 us: 10^5 steps unscaled, 2.8e4 with the target 2 us (first period then ~10 ms)
  const double length = 0.1, b = 0.005, load = 50.0;
  Model m(make_box_mesh({Vec3::Zero(), Vec3(length, b, b), {20, 1, 1}, ElementType::Hex8}),
          Material{kE, kNu, kRho});
  m.fix("xmin");
  const double ramp = 0.04;
  m.add_traction("xmax", Vec3(0, 0, -load / (b * b)), [ramp](double t) {
    return t < ramp ? 0.5 * (1.0 - std::cos(M_PI * t / ramp)) : 1.0;
  });
  Model static_model = m;
  SolverOptions o = scaled(2e-6);
  o.rayleigh_alpha = 250.0;  // ~20 % of critical in the scaled first mode
  StructuralSolver s(std::move(m), o);
  REQUIRE(s.mass_scaled_elements() > 0);
  const double dt = 0.9 * s.stable_time_step();
  while (s.time() < ramp + 0.01) s.step(dt);
  StructuralSolver reference(std::move(static_model));
  reference.step_static(ramp + 0.01);  // the full load
  const auto tip = s.mesh().node_set("xmax");
  double w = 0.0, w_static = 0.0;
  for (auto node : tip) {
    w += s.displacement(node).z() / static_cast<double>(tip.size());
    w_static += reference.displacement(node).z() / static_cast<double>(tip.size());
  }
  const double inertia = b * b * b * b / 12.0;
  const double euler_bernoulli = -load * length * length * length / (3.0 * kE * inertia);
  INFO("tip deflection " << w << " m, static solve " << w_static << " m, Euler-Bernoulli "
                         << euler_bernoulli << " m, " << s.step_count() << " steps, added mass "
                         << s.added_mass() / s.physical_mass() * 100 << " %");
  CHECK(w == Approx(w_static).epsilon(0.01));
  CHECK(w == Approx(euler_bernoulli).epsilon(0.03));
}

TEST_CASE("mass scaling: refused outside central difference", "[fem][explicit][mass-scaling]") {
  SolverOptions o;
  o.mass_scaling_time_step = 1e-6;
  CHECK_THROWS_WITH(StructuralSolver(rod(1.0, 2), o), Catch::Contains("central-difference"));
  CHECK_THROWS_WITH(StructuralSolver(rod(1.0, 2), scaled(-1.0)), Catch::Contains(">= 0"));
}

TEST_CASE("element length V / A_max: a box's thinnest side, a tetrahedron's, 0 inside out",
          "[fem][explicit][element-step]") {
  const Model box(make_box_mesh({Vec3::Zero(), Vec3(0.3, 0.2, 0.05), {1, 1, 1}, ElementType::Hex8}),
                  Material{kE, kNu, kRho});
  const Element& e = box.mesh().elements()[0];
  ElementCoordinates x = element_coordinates(box.mesh(), e);
  CHECK(element_length(e.type, x) == Approx(0.05).epsilon(1e-12));
  x.col(2) *= -1.0;  // mirrored: turned inside out
  CHECK(element_length(e.type, x) == 0.0);
  ElementCoordinates t(4, 3);
  t << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  // V = 1/6, the largest face the slanted one, sqrt(3)/2
  CHECK(element_length(ElementType::Tet4, t) == Approx((1.0 / 6.0) / (std::sqrt(3.0) / 2.0)).epsilon(1e-12));
}

TEST_CASE("the elements' stable step at their present shape: the step at rest, shrinking with "
          "a squeezed element", "[fem][explicit][element-step]") {
  // cube elements of the rod (y, z fixed): at rest each element's step is h / c_d (with the
  // scaled mass 3 h / c_d), the stable step; the rod shortened by 20 % (a static solve with its
  // end displaced) makes every element 0.8 h long, so its step 0.8 times that
  const double length = 1.0, a = 0.02;
  const int n = 50;
  const double dt_e = (length / n) / dilatational_speed();
  Model m = rod(length, n, a);
  m.fix("xmin", {0});
  m.prescribe("xmax", 0, [](double t) { return -0.2 * t; });  // (at rest at t = 0)
  StructuralSolver s(std::move(m), scaled(3.0 * dt_e));
  CHECK(s.min_element_time_step() == Approx(s.stable_time_step()).epsilon(1e-12));
  CHECK(s.min_element_time_step() == Approx(3.0 * dt_e).epsilon(1e-12));
  s.step_static(1.0);
  CHECK(s.min_element_time_step() == Approx(0.8 * 3.0 * dt_e).epsilon(1e-9));
}
