// The EAS Hex8 of the nonlinear path (for thin plates that bend and yield): enhanced
// assumed strain after Simo & Armero (1992) / Simo, Armero & Taylor (1993), 9 modes with
// Taylor's constant-Jacobian scaling, 6 Gauss points through a thin element's thickness.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <string>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using partita::fem::test::tip_deflection;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;

std::shared_ptr<const MaterialLaw> elastic_j2() {
  return std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(1e12, 0.0));
}

// Plate strip L = 1 m, h = 10 mm (L/h = 100), b = 50 mm: 40 x 1 x 1 Hex8 (one element through
// the thickness; each 25 x 50 x 10 mm: thin, so 2 x 2 x 6 points), tip load P as a shear
// traction on x = L. `sliding`: the root holds u_x and u_z only (and u_y on one edge), so that
// the root section contracts freely as beam theory assumes; else clamped.
Model strip(std::shared_ptr<const MaterialLaw> law, double p, bool sliding,
            Hex8Formulation hex8 = Hex8Formulation::IncompatibleModes) {
  constexpr double l = 1.0, b = 0.05, h = 0.01;
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(l, b, h), {40, 1, 1}, ElementType::Hex8});
  mesh.add_node_set_where("root_edge",
                          [](const Vec3& x) { return x.x() < 1e-12 && x.y() < 1e-12; });
  Model m(std::move(mesh));
  m.set_material_law(std::move(law));
  m.set_hex8_formulation(hex8);
  if (sliding) {
    m.fix("xmin", {0, 2});
    m.fix("root_edge", {1});
  } else {
    m.fix("xmin");
  }
  m.add_traction("xmax", Vec3(0.0, 0.0, -p / (b * h)), [](double t) { return t; });
  return m;
}

}  // namespace

TEST_CASE("EAS Hex8: patch test, a homogeneous deformation of a distorted mesh is exact",
          "[fem][nonlinear][eas]") {
  Mat3 f0;
  f0 << 1.10, 0.05, 0.0, 0.02, 0.95, 0.03, 0.01, 0.0, 1.05;
  for (auto law : std::vector<std::shared_ptr<const MaterialLaw>>{
           std::make_shared<NeoHookeLaw>(kE, kNu, kRho), elastic_j2()}) {
    INFO(law->name());
    // 2 x 1 x 1 box of 2 x 2 x 2 cells, the interior node moved; and a thin one (2 x 2 x 6 rule)
    for (double depth : {1.0, 0.2}) {
      // the law's stress at F0 at every point (the enhanced modes stay at zero), the interior
      // node in equilibrium
      test::check_homogeneous_patch(test::distorted_box(ElementType::Hex8, depth, law, 5), f0, *law);
    }
  }
}

TEST_CASE("EAS Hex8: the condensed tangent equals finite differences", "[fem][nonlinear][eas]") {
  SECTION("neo-hooke, large deformation, thick and thin elements") {
    for (double depth : {1.0, 0.2}) {
      Model m = test::distorted_box(ElementType::Hex8, depth,
                                    std::make_shared<NeoHookeLaw>(1e6, 0.3, 1000.0), 3);
      NonlinearOperator op(m);
      CHECK(test::tangent_fd_error(op, test::large_deformation(m.mesh(), 4), 1e-6, 4, 21) < 1e-6);
    }
  }
  SECTION("small-strain j2 from a plastic history") {
    Model m = test::distorted_box(
        ElementType::Hex8, 0.2,
        std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kE / 20.0)),
        5);
    NonlinearOperator op(m);
    test::Lcg rng(9);
    Eigen::VectorXd u(3 * static_cast<Eigen::Index>(m.mesh().num_nodes())), f;
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = 0.01 * rng.next();
    op.evaluate(u, f, nullptr);
    op.commit();
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += 0.004 * rng.next();
    CHECK(test::tangent_fd_error(op, u, 1e-9, 4, 13) < 1e-6);
  }
}

TEST_CASE(
    "EAS Hex8: a plate strip L/h = 100 with one element through the thickness bends as "
    "Euler-Bernoulli, where plain Hex8 locks",
    "[fem][nonlinear][eas]") {
  constexpr double l = 1.0, b = 0.05, h = 0.01, p = 10.0;
  const double eb = p * l * l * l / (3.0 * kE * b * h * h * h / 12.0);
  for (auto law : std::vector<std::shared_ptr<const MaterialLaw>>{
           elastic_j2(), std::make_shared<NeoHookeLaw>(kE, kNu, kRho)}) {
    INFO(law->name());
    StructuralSolver s(strip(law, p, false));
    s.step_static(1.0);
    const double w = tip_deflection(s);
    WARN("EAS strip " << law->name() << ": tip deflection / Euler-Bernoulli = " << w / eb);
    CHECK(w / eb == Approx(1.0).margin(0.03));
  }
  StructuralSolver plain(strip(elastic_j2(), p, false, Hex8Formulation::Full));
  plain.step_static(1.0);
  CHECK(tip_deflection(plain) / eb < 0.5);  // shear locking
}

TEST_CASE(
    "EAS Hex8: the perfectly plastic plate strip collapses within 5 % of its plastic "
    "limit load",
    "[fem][nonlinear][eas][limit]") {
  // A strip b = 5 h wide bends cylindrically at its hinge (the width keeps the plastic flow from
  // contracting it sideways: eps_yy = 0), so its plastic moment is the plane-strain von Mises
  // one, M_p = (2 / sqrt 3) sigma_y b h^2 / 4, and the tip load it carries P_L = M_p / L. Beam
  // theory's uniaxial sigma_y b h^2 / (4 L) is 13 % lower (a lower bound: the strip is stronger).
  constexpr double l = 1.0, b = 0.05, h = 0.01;
  const double limit = 2.0 / std::sqrt(3.0) * kSy * b * h * h / (4.0 * l);
  auto j2 = std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0));
  SolverOptions opt;
  opt.newton.load_steps = 10;
  StructuralSolver s(strip(j2, 1.1 * limit, true), opt);
  std::string what;
  const auto lambda = partita::fem::test::limit_load_factor(s, what);
  INFO(what);
  REQUIRE(lambda.has_value());
  const double collapse = 1.1 * *lambda;  // in units of P_L
  WARN("EAS strip: collapse load / plane-strain P_L = " << collapse);
  CHECK(collapse == Approx(1.0).margin(0.05));
}

TEST_CASE("EAS Hex8: the thin strip in Newmark and central-difference dynamics, energy balance",
          "[fem][nonlinear][eas]") {
  for (auto integrator : {Integrator::Newmark, Integrator::CentralDifference}) {
    for (auto law : std::vector<std::shared_ptr<const MaterialLaw>>{
             elastic_j2(), std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho,
                                                               HardeningCurve::linear(kSy, 0.0))}) {
      INFO(law->name() << (integrator == Integrator::Newmark ? " newmark" : " central difference"));
      Model m = strip(law, 0.0, false);
      m.add_traction("xmax", Vec3(0.0, 0.0, -2e6));  // suddenly applied
      SolverOptions opt;
      opt.integrator = integrator;
      if (integrator == Integrator::CentralDifference) opt.mass = MassType::Lumped;
      StructuralSolver s(std::move(m), opt);
      const double dt = integrator == Integrator::Newmark ? 1e-4 : 0.5 * s.stable_time_step();
      const int steps = integrator == Integrator::Newmark ? 50 : 400;
      for (int i = 0; i < steps; ++i) s.step(dt);
      REQUIRE(s.external_work() > 0.0);
      CHECK(tip_deflection(s) > 0.0);
      CHECK(std::abs(s.energy_balance()) < 2e-2 * s.external_work());
    }
  }
}
