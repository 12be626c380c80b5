// Finite-strain J2 (multiplicative, logarithmic strains): uniaxial tension to 50 % stretch and
// back against the 1D model in log strain, objectivity, Newton convergence.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <sstream>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 200e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6, kH = 2e9;

// 1D elastoplasticity with linear isotropic hardening (Simo & Hughes 1998, Box 1.4) in the
// log strain eps = ln(lambda) and the Kirchhoff stress tau: what the exponential-map model
// reduces to for a coaxial uniaxial-stress path.
struct LogStrainReference {
  double eps_p = 0.0, alpha = 0.0;
  double tau(double eps) {
    const double trial = kE * (eps - eps_p);
    const double f = std::abs(trial) - (kSy + kH * alpha);
    if (f <= 0.0) return trial;
    const double dg = f / (kE + kH), sign = trial > 0 ? 1.0 : -1.0;
    eps_p += dg * sign;
    alpha += dg;
    return trial - kE * dg * sign;
  }
};

}  // namespace

TEST_CASE("finite-strain j2: uniaxial stretch to 1.5 and back follows the 1D log-strain model",
          "[fem][nonlinear][j2][finite-strain]") {
  auto law = std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(law);
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  // stretch lambda(t) = 1 + 0.5 t up to t = 1, then back to 1.2 at t = 2
  auto stretch = [](double t) { return t <= 1.0 ? 1.0 + 0.5 * t : 1.5 - 0.3 * (t - 1.0); };
  m.prescribe("xmax", 0, [stretch](double t) { return stretch(t) - 1.0; });
  SolverOptions opt;
  opt.newton.force_tolerance = 1e-11;
  StructuralSolver s(std::move(m), opt);
  LogStrainReference ref;
  double worst = 0.0;
  for (int k = 0; k < 40; ++k) {
    s.step_static(0.05);
    const double lambda = stretch(s.time());
    // reaction = P_11 A_0 = tau_11 / lambda (unit reference area)
    const double expected = ref.tau(std::log(lambda)) / lambda;
    worst = std::max(worst, std::abs(s.reaction("xmax")[0] - expected));
  }
  INFO("largest deviation " << worst << " Pa");
  CHECK(worst <= 1e-8 * kSy);
  CHECK(s.equivalent_plastic_strain().maxCoeff() == Approx(ref.alpha).epsilon(1e-9));
}

TEST_CASE("finite-strain j2: a rigid rotation after plastic flow rotates the stress only",
          "[fem][nonlinear][j2][finite-strain]") {
  FiniteStrainJ2Law law(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
  std::vector<double> committed(14), trial(14), trial2(14);
  law.initialise_state(committed);
  Mat3 f;
  f << 1.3, 0.1, 0.0, 0.05, 0.85, 0.02, 0.0, 0.03, 0.9;
  MaterialResponse r1, r2;
  law.evaluate(f, committed, trial, r1);
  REQUIRE(trial[6] > 0.0);  // it yielded
  committed = trial;
  // the same F again: nothing new happens (the state is on the yield surface, elastic)
  law.evaluate(f, committed, trial, r1);
  // superpose a rotation R: P(R F) = R P(F), same history (objectivity)
  const Mat3 rot = Eigen::AngleAxisd(1.1, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  law.evaluate(rot * f, committed, trial2, r2);
  CHECK((r2.stress - rot * r1.stress).norm() <= 1e-9 * r1.stress.norm());
  CHECK(std::abs(trial2[6] - trial[6]) <= 1e-12);
  CHECK(r2.energy_density == Approx(r1.energy_density).epsilon(1e-10));
}

TEST_CASE("finite-strain j2: Newton converges quadratically in plastic bending",
          "[fem][nonlinear][j2][finite-strain][slow]") {
  const test::BendingRun run = test::plastic_bending(
      std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho, HardeningCurve::linear(kSy, kE / 50.0)),
      0.5, 1e-9, 4);
  const NewtonReport& rep = run.report;
  REQUIRE(rep.converged);
  WARN("finite-strain j2 plastic bending, relative Newton residuals: " << run.residuals);
  CHECK(run.max_plastic_strain > 0.0);
  // the finite-difference tangent is accurate to ~1e-9: quadratic above 1e-7
  const test::QuadraticCheck q = test::check_quadratic(rep, 1e-7);
  CHECK(q.checked >= 1);
  CHECK(q.violations == 0);
}
