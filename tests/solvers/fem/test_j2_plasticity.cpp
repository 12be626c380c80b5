// Small-strain J2 plasticity: one element against the 1D elastoplastic model, quadratic Newton
// convergence, the algorithmic tangent against finite differences, input validation.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 200e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;

// The 1D rate-independent model with linear isotropic hardening (Simo & Hughes 1998, section
// 1.4, Box 1.4): sigma = E (eps - eps_p), |sigma| <= sigma_y + H alpha. A uniaxial stress
// state of the 3D J2 law must follow it exactly (von Mises reduces to |sigma| there).
struct OneDimensionalPlasticity {
  double e, sy, h;
  double eps_p = 0.0, alpha = 0.0;
  double stress(double eps) {
    const double trial = e * (eps - eps_p);
    const double f = std::abs(trial) - (sy + h * alpha);
    if (f <= 0.0) return trial;
    const double dg = f / (e + h);
    const double sign = trial > 0 ? 1.0 : -1.0;
    eps_p += dg * sign;
    alpha += dg;
    return trial - e * dg * sign;
  }
};

// Unit cube, one Hex8, symmetry planes xmin/ymin/zmin, u_x = strain(t) on xmax (uniaxial stress).
Model uniaxial_cube(std::shared_ptr<const MaterialLaw> law, std::function<double(double)> strain) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::move(law));
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  m.prescribe("xmax", 0, std::move(strain));
  return m;
}

}  // namespace

TEST_CASE("j2 one element: loading, unloading and reverse yield follow the 1D model exactly",
          "[fem][nonlinear][j2]") {
  const double h = kE / 10.0;
  auto law = std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, h));
  const double eps_y = kSy / kE;
  // strain path: 0 -> 4 eps_y (yield, hardening) -> -3 eps_y (elastic unloading, reverse yield)
  auto path = [eps_y](double t) { return t <= 4.0 ? t * eps_y : (8.0 - t) * eps_y; };
  SolverOptions opt;
  opt.newton.force_tolerance = 1e-12;
  StructuralSolver s(uniaxial_cube(law, path), opt);
  OneDimensionalPlasticity ref{kE, kSy, h};
  double worst = 0.0;
  for (int k = 1; k <= 44; ++k) {  // steps of eps_y / 4
    s.step_static(0.25);
    const double expected = ref.stress(path(s.time()));
    worst = std::max(worst, std::abs(s.reaction("xmax")[0] - expected));
  }
  // stresses ~ sigma_y: relative 1e-9 of the yield stress
  CHECK(worst <= 1e-9 * kSy);
  // closed form at the peak (t = 4): sigma = sigma_y + E H / (E + H) (eps - eps_y)
  OneDimensionalPlasticity check{kE, kSy, h};
  CHECK(check.stress(4.0 * eps_y) == Approx(kSy + kE * h / (kE + h) * 3.0 * eps_y).epsilon(1e-14));
  // plastic work of the path, 1D: sum sigma d eps_p; the 3D history integrates the same
  CHECK(s.plastic_work() > 0.0);
}

TEST_CASE("j2 tabulated hardening: one element follows the table", "[fem][nonlinear][j2]") {
  // sigma_y(alpha): 250 MPa, 300 MPa at 0.002, 320 MPa at 0.01, flat beyond
  auto law = std::make_shared<J2PlasticityLaw>(
      kE, kNu, kRho, HardeningCurve::tabulated({{0.0, 250e6}, {0.002, 300e6}, {0.01, 320e6}}));
  const double eps_end = 0.02;
  SolverOptions opt;
  opt.newton.force_tolerance = 1e-12;
  StructuralSolver s(uniaxial_cube(law, [eps_end](double t) { return t * eps_end; }), opt);
  for (int k = 1; k <= 40; ++k) {
    s.step_static(1.0 / 40.0);
    const double eps = s.time() * eps_end;
    // uniaxial: sigma = sigma_y(alpha) with alpha = eps - sigma / E once yielding; solve for
    // sigma on the table (monotone) by bisection
    double expected = kE * eps;
    if (expected > 250e6) {
      const HardeningCurve table =
          HardeningCurve::tabulated({{0.0, 250e6}, {0.002, 300e6}, {0.01, 320e6}});
      expected = test::bisect([&](double sig) { return sig - table.yield_stress(eps - sig / kE); },
                              250e6, 320e6);
    }
    CHECK(std::abs(s.reaction("xmax")[0] - expected) <= 1e-9 * kSy);
  }
}

TEST_CASE("j2 consistent tangent: quadratic Newton convergence in plastic bending",
          "[fem][nonlinear][j2]") {
  // cantilever 10 x 1 x 1 (Hex20), clamped at x = 0, tip pushed down until it yields: first
  // yield of the root fibre at a tip deflection of about 2 sigma_y L^2 / (3 E h) = 0.083
  const test::BendingRun run = test::plastic_bending(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kE / 50.0)), 0.2,
      1e-10, 2);
  const NewtonReport& rep = run.report;
  REQUIRE(rep.converged);
  WARN("j2 plastic bending, relative Newton residuals: " << run.residuals);
  CHECK(run.max_plastic_strain > 0.0);  // it did yield
  const test::QuadraticCheck q = test::check_quadratic(rep, 1e-15);
  CHECK(q.checked >= 1);
  CHECK(q.violations == 0);
}

TEST_CASE("j2 algorithmic tangent equals finite differences from a plastic history",
          "[fem][nonlinear][j2]") {
  Model m = test::distorted_box(
      ElementType::Hex20, 1.0,
      std::make_shared<J2PlasticityLaw>(
          kE, kNu, kRho, HardeningCurve::tabulated({{0.0, 250e6}, {0.01, 300e6}, {0.05, 330e6}})),
      5);
  NonlinearOperator op(m);
  test::Lcg rng(9);
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(m.mesh().num_nodes())), f;
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = 0.01 * rng.next();  // strains ~ 1e-2
  op.evaluate(u, f, nullptr);
  op.commit();  // a plastic history
  Eigen::VectorXd u2 = u;
  for (Eigen::Index i = 0; i < u.size(); ++i) u2[i] += 0.004 * rng.next();
  // central differences with h far below the increment (no point crosses the yield surface)
  CHECK(test::tangent_fd_error(op, u2, 1e-9, 4, 13) < 1e-6);
}

TEST_CASE("j2 radial return: exact for linear hardening, a clear error for a crushed element",
          "[fem][nonlinear][j2]") {
  // r(dg) = |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha_n + sqrt(2/3) dg) = 0 in closed form for
  // linear hardening: dg = (|s_tr| - sqrt(2/3) sigma_y(alpha_n)) / (2 G + 2/3 H)
  const double g = kE / (2.0 * (1.0 + kNu)), h = 1e9;
  for (const HardeningCurve& curve :
       {HardeningCurve::linear(kSy, h),
        HardeningCurve::tabulated({{0.0, kSy}, {0.01, kSy + 0.01 * h}, {10.0, kSy + 10.0 * h}})}) {
    for (double factor : {1.5, 10.0, 100.0}) {
      const double trial = factor * kSy;
      const double exact = (trial - std::sqrt(2.0 / 3.0) * kSy) / (2.0 * g + 2.0 / 3.0 * h);
      CHECK(curve.return_map_increment(g, trial, 0.0) == Approx(exact).epsilon(1e-12));
    }
    // a trial stress of 1e5 yield stresses (a strain increment of ~100 in one step: an element
    // crushed at once) is refused with what it means, not returned
    CHECK_THROWS_WITH(curve.return_map_increment(g, 1e5 * kSy, 0.0),
                      Catch::Contains("times the yield stress") && Catch::Contains("crushed"));
  }
}

TEST_CASE("j2 rejects bad input", "[fem][nonlinear][j2]") {
  CHECK_THROWS_WITH(HardeningCurve::linear(-1e6, 1e9), Catch::Contains("yield stress must be > 0"));
  CHECK_THROWS_WITH(HardeningCurve::linear(250e6, -1e9), Catch::Contains("hardening modulus"));
  CHECK_THROWS_WITH(HardeningCurve::tabulated({{0.0, 250e6}, {0.01, 300e6}, {0.01, 310e6}}),
                    Catch::Contains("strictly increasing in strain"));
  CHECK_THROWS_WITH(HardeningCurve::tabulated({{0.0, 250e6}, {0.02, 300e6}, {0.01, 310e6}}),
                    Catch::Contains("strictly increasing in strain"));
  CHECK_THROWS_WITH(HardeningCurve::tabulated({{0.0, -250e6}}), Catch::Contains("> 0"));
  CHECK_THROWS_WITH(HardeningCurve::tabulated({{0.001, 250e6}}), Catch::Contains("start at"));
  CHECK_THROWS_AS(HardeningCurve::tabulated({}), Error);
  CHECK_THROWS_AS(J2PlasticityLaw(kE, 0.5, kRho, HardeningCurve::linear(kSy, 0.0)), Error);
}

TEST_CASE("nonlinear static: a load above the limit load stops with the limit-load message",
          "[fem][nonlinear]") {
  // perfectly plastic bar pulled beyond its limit load by a force: no equilibrium exists
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.1, 0.1), {2, 1, 1}, ElementType::Hex8}));
  m.set_material_law(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0)));
  m.fix("xmin", {0});  // symmetry planes: a uniaxial stress state, limit load sigma_y A
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  // ask for twice the limit load
  m.add_traction("xmax", Vec3(2.0 * kSy, 0, 0), [](double t) { return t; });
  SolverOptions opt;
  opt.newton.max_cutbacks = 3;
  StructuralSolver s(std::move(m), opt);
  // the bar yields all at once at half the load: the largest load factor is 0.5
  CHECK_THROWS_WITH(s.step_static(1.0),
                    Catch::Contains("limit load") &&
                        Catch::Contains("the largest load factor reached is 0.5 ") &&
                        Catch::Contains("halvings"));
}

TEST_CASE("j2 energy balance: external work = elastic energy + plastic work, load and unload",
          "[fem][nonlinear][j2][energy]") {
  // One element in uniaxial stress under a traction that ramps to 1.5 sigma_y and back to 0 in
  // steps of sigma_y / 4 (one step ends exactly at first yield). With linear hardening the
  // response is piecewise linear in the load inside every step, so the trapezoidal external
  // work and the trapezoidal plastic work are exact: the balance holds to round-off.
  const double h = kE / 10.0;
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, h)));
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  m.add_traction("xmax", Vec3(kSy, 0, 0),
                 [](double t) { return t <= 6.0 ? t / 4.0 : (12.0 - t) / 4.0; });
  SolverOptions opt;
  opt.newton.force_tolerance = 1e-12;
  StructuralSolver s(std::move(m), opt);
  for (int k = 0; k < 12; ++k) s.step_static(1.0);
  // 1D: plastic strain at the peak (1.5 sigma_y) = 0.5 sigma_y / H; W_p = int sigma d eps_p
  // = (sigma_y + 1.5 sigma_y) / 2 * 0.5 sigma_y / H; nothing stored after unloading
  const double wp = 0.5 * (kSy + 1.5 * kSy) * 0.5 * kSy / h;
  CHECK(s.plastic_work() == Approx(wp).epsilon(1e-10));
  CHECK(std::abs(s.strain_energy()) <= 1e-10 * wp);
  CHECK(std::abs(s.energy_balance()) <= 1e-10 * wp);
}

TEST_CASE("j2 output: the element equivalent plastic strain of a uniaxial test",
          "[fem][nonlinear][j2][output]") {
  const double h = kE / 10.0;
  const double eps_y = kSy / kE;
  StructuralSolver s(uniaxial_cube(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, h)),
      [eps_y](double t) { return 3.0 * eps_y * t; }));
  s.step_static(1.0);
  // uniaxial, linear hardening: eps_p = (sigma - sigma_y) / H with sigma from the 1D model
  OneDimensionalPlasticity ref{kE, kSy, h};
  ref.stress(3.0 * eps_y);
  REQUIRE(s.element_equivalent_plastic_strain().size() == 1);
  CHECK(s.element_equivalent_plastic_strain()[0] == Approx(ref.alpha).epsilon(1e-9));
  // (the FEM adapter writes it as the cell array equivalent_plastic_strain of the .vtu:
  // tests/adapters/test_output.cpp)
}
