// Strain-rate hardening of the J2 laws (Cowper-Symonds on the equivalent plastic strain rate):
// uniaxial stress at constant strain rate against sigma_y (1 + (rate / D)^(1/q)), the
// rate-independent limit, the consistent tangent against finite differences, the finite-strain
// law in Kirchhoff stress and log strain, and the solver passing its time step to the laws.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <vector>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/strain_rate_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 200e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;
constexpr double kD = 40.4, kQ = 5.0;  // mild steel (Jones, Structural Impact, ch. 8)

// Cowper-Symonds: sigma_y,dyn / sigma_y
double dynamic_factor(double rate) {
  return 1.0 + std::pow(rate / kD, 1.0 / kQ);
}

// One material point in uniaxial stress: F = diag(a, l, l) with the lateral l found by Newton on
// P_yy = 0 (the law's own tangent), the history committed after each step.
struct UniaxialPoint {
  const MaterialLaw& law;
  std::vector<double> committed, trial;
  double lateral = 1.0;
  MaterialResponse r;

  explicit UniaxialPoint(const MaterialLaw& l)
      : law(l), committed(static_cast<std::size_t>(l.state_size())), trial(committed.size()) {
    law.initialise_state(committed);
  }
  // P at axial stretch (F_xx) a over `step`; commits. Returns P_xx.
  double load(double a, const MaterialStep& step) {
    for (int it = 0; it < 60; ++it) {
      Mat3 f = Mat3::Zero();
      f(0, 0) = a;
      f(1, 1) = f(2, 2) = lateral;
      law.evaluate_step(f, committed, trial, step, r);
      const double residual = r.stress(1, 1);
      if (std::abs(residual) <= 1e-9 * kSy) {
        committed = trial;
        return r.stress(0, 0);
      }
      // dP_yy / dl = A_yyyy + A_yyzz (index 3 i + J)
      lateral -= residual / (r.tangent(4, 4) + r.tangent(4, 8));
    }
    FAIL("lateral Newton did not converge");
    return 0.0;
  }
  double alpha() const { return law.equivalent_plastic_strain(committed); }
};

MaterialStep dynamic_step(double dt) {
  MaterialStep s;
  s.time_increment = dt;
  s.dynamic = true;
  return s;
}

}  // namespace

TEST_CASE("cowper-symonds: small-strain uniaxial flow stress at constant strain rate",
          "[fem][j2][rate]") {
  const double eps_y = kSy / kE, h = kE / 100.0;
  for (const double rate : {1.0, 100.0, 1e4}) {
    INFO("strain rate " << rate << " 1/s");
    // with hardening: each plastic step's stress is sigma_y(alpha) (1 + (d alpha / dt / D)^(1/q))
    {
      const J2PlasticityLaw law(kE, kNu, kRho, HardeningCurve::linear(kSy, h),
                                CowperSymonds(kD, kQ));
      UniaxialPoint p(law);
      const double de = 0.5 * eps_y, dt = de / rate;
      int plastic_steps = 0;
      for (int k = 1; k <= 40; ++k) {
        const double alpha_n = p.alpha();
        const double sigma = p.load(1.0 + k * de, dynamic_step(dt));
        const double d_alpha = p.alpha() - alpha_n;
        if (d_alpha <= 0.0) continue;
        ++plastic_steps;
        const double expected = (kSy + h * p.alpha()) * dynamic_factor(d_alpha / dt);
        CHECK(std::abs(sigma - expected) <= 1e-6 * expected);
      }
      CHECK(plastic_steps > 30);
    }
    // perfect plasticity: in steady flow the elastic strain is constant, so the plastic strain
    // rate is the imposed one and sigma = sigma_y (1 + (rate / D)^(1/q)), a closed form
    {
      const J2PlasticityLaw law(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0),
                                CowperSymonds(kD, kQ));
      UniaxialPoint p(law);
      const double de = 0.5 * eps_y, dt = de / rate;
      double sigma = 0.0;
      for (int k = 1; k <= 60; ++k) sigma = p.load(1.0 + k * de, dynamic_step(dt));
      CHECK(std::abs(sigma - kSy * dynamic_factor(rate)) <= 1e-6 * kSy);
    }
  }
}

TEST_CASE("cowper-symonds: static steps and vanishing rates give the rate-independent law",
          "[fem][j2][rate]") {
  const double eps_y = kSy / kE, h = kE / 100.0;
  const J2PlasticityLaw plain(kE, kNu, kRho, HardeningCurve::linear(kSy, h));
  const J2PlasticityLaw rated(kE, kNu, kRho, HardeningCurve::linear(kSy, h), CowperSymonds(kD, kQ));
  UniaxialPoint reference(plain), statics(rated), slow(rated);
  // a rate of D 1e-40: (rate / D)^(1/q) = 1e-8
  const double de = 0.5 * eps_y, dt = de / (1e-40 * kD);
  for (int k = 1; k <= 30; ++k) {
    const double a = 1.0 + k * de;
    const double sigma_ref = reference.load(a, MaterialStep{});
    // a static step (dynamic false) is the law without the rate term, bit for bit
    MaterialStep static_step;
    static_step.time_increment = dt;
    CHECK(statics.load(a, static_step) == sigma_ref);
    CHECK(std::abs(slow.load(a, dynamic_step(dt)) - sigma_ref) <= 1e-6 * sigma_ref);
  }
  CHECK(reference.alpha() > 10.0 * eps_y);
  // a dynamic evaluation at the committed instant (dt = 0) has no time to flow: elastic, the
  // plastic strain as committed
  UniaxialPoint instant(rated);
  const double sigma = instant.load(1.0 + 4.0 * eps_y, dynamic_step(0.0));
  CHECK(instant.alpha() == 0.0);
  CHECK(sigma > 3.0 * kSy);
}

TEST_CASE("cowper-symonds: the consistent tangent matches finite differences", "[fem][j2][rate]") {
  for (const double hardening : {0.0, kE / 50.0}) {
    const J2PlasticityLaw law(kE, kNu, kRho, HardeningCurve::linear(kSy, hardening),
                              CowperSymonds(kD, kQ));
    // a committed plastic state, then a general strain increment over dt
    std::vector<double> committed(14), trial(14);
    law.initialise_state(committed);
    MaterialResponse r;
    Mat3 f0 = Mat3::Identity();
    f0(0, 0) += 3e-3;
    f0(0, 1) += 1e-3;
    law.evaluate_step(f0, committed, trial, dynamic_step(1e-4), r);
    REQUIRE(law.equivalent_plastic_strain(trial) > 0.0);
    committed = trial;
    Mat3 f = f0;
    f(1, 1) -= 1.5e-3;
    f(2, 0) += 2e-3;
    f(1, 2) += 0.5e-3;
    for (const double dt : {1e-6, 1e-4, 1e-2}) {
      INFO("H = " << hardening << ", dt = " << dt);
      const MaterialStep step = dynamic_step(dt);
      law.evaluate_step(f, committed, trial, step, r);
      REQUIRE(law.equivalent_plastic_strain(trial) > law.equivalent_plastic_strain(committed));
      const Matrix9 a = r.tangent;
      constexpr double dh = 1e-8;
      Matrix9 fd;
      MaterialResponse rp, rm;
      std::vector<double> scratch(14);
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          Mat3 fp = f, fm = f;
          fp(k, l) += dh;
          fm(k, l) -= dh;
          law.evaluate_step(fp, committed, scratch, step, rp);
          law.evaluate_step(fm, committed, scratch, step, rm);
          const Mat3 d = (rp.stress - rm.stress) / (2.0 * dh);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) fd(3 * i + j, 3 * k + l) = d(i, j);
        }
      }
      CHECK((a - fd).cwiseAbs().maxCoeff() <= 1e-6 * a.cwiseAbs().maxCoeff());
      // the rate term stiffens the plastic response against the rate-independent law's
      const J2PlasticityLaw plain(kE, kNu, kRho, HardeningCurve::linear(kSy, hardening));
      MaterialResponse r0;
      plain.evaluate(f, committed, scratch, r0);
      CHECK(r.stress.norm() > r0.stress.norm());
    }
  }
}

TEST_CASE("cowper-symonds: finite-strain uniaxial Kirchhoff stress at constant log strain rate",
          "[fem][j2][rate]") {
  const double h = kE / 100.0;
  for (const double rate : {1.0, 100.0, 1e4}) {
    INFO("log strain rate " << rate << " 1/s");
    // steps of d ln(a) = 0.005 to a log strain of 0.3: stretch a = exp(rate t)
    const double de = 0.005, dt = de / rate;
    {
      const FiniteStrainJ2Law law(kE, kNu, kRho, HardeningCurve::linear(kSy, h),
                                  CowperSymonds(kD, kQ));
      UniaxialPoint p(law);
      for (int k = 1; k <= 60; ++k) {
        const double a = std::exp(k * de), alpha_n = p.alpha();
        // tau = P F^T: tau_xx = P_xx a (the Cauchy, true stress is tau / J)
        const double tau = p.load(a, dynamic_step(dt)) * a;
        const double d_alpha = p.alpha() - alpha_n;
        REQUIRE(d_alpha > 0.0);
        const double expected = (kSy + h * p.alpha()) * dynamic_factor(d_alpha / dt);
        CHECK(std::abs(tau - expected) <= 1e-6 * expected);
      }
      CHECK(p.alpha() > 0.25);
    }
    {
      // perfect plasticity, steady flow: the plastic log strain rate is the imposed one
      const FiniteStrainJ2Law law(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0),
                                  CowperSymonds(kD, kQ));
      UniaxialPoint p(law);
      double tau = 0.0;
      for (int k = 1; k <= 60; ++k)
        tau = p.load(std::exp(k * de), dynamic_step(dt)) * std::exp(k * de);
      CHECK(std::abs(tau - kSy * dynamic_factor(rate)) <= 1e-6 * kSy);
    }
  }
  // the static step is the rate-independent finite-strain law, bit for bit
  const FiniteStrainJ2Law plain(kE, kNu, kRho, HardeningCurve::linear(kSy, h));
  const FiniteStrainJ2Law rated(kE, kNu, kRho, HardeningCurve::linear(kSy, h),
                                CowperSymonds(kD, kQ));
  UniaxialPoint a(plain), b(rated);
  for (int k = 1; k <= 20; ++k)
    CHECK(b.load(std::exp(0.005 * k), MaterialStep{}) ==
          a.load(std::exp(0.005 * k), MaterialStep{}));
}

TEST_CASE("cowper-symonds: bad constants are refused", "[fem][j2][rate]") {
  CHECK_THROWS_WITH(CowperSymonds(0.0, 5.0), Catch::Contains("D must be"));
  CHECK_THROWS_WITH(CowperSymonds(40.4, -1.0), Catch::Contains("q must be"));
  MaterialLawRegistry laws;
  register_material_laws(laws);
  MaterialParameters p;
  p.set("youngs_modulus", kE)
      .set("poisson_ratio", kNu)
      .set("density", kRho)
      .set("yield_stress", kSy);
  for (const char* name : {"j2-plasticity", "j2-plasticity-finite-strain"}) {
    MaterialParameters only_d = p;
    only_d.set("cowper_symonds_d", 40.4);
    CHECK_THROWS_WITH(laws.get(name).create(only_d), Catch::Contains("cowper_symonds_q"));
    MaterialParameters negative = p;
    negative.set("cowper_symonds_d", -40.4).set("cowper_symonds_q", 5.0);
    CHECK_THROWS_WITH(laws.get(name).create(negative),
                      Catch::Contains("cowper_symonds_d must be > 0"));
    MaterialParameters both = p;
    both.set("cowper_symonds_d", 40.4).set("cowper_symonds_q", 5.0);
    CHECK(laws.get(name).create(both) != nullptr);
  }
}

namespace {

// A unit cube, one Hex8, symmetry planes xmin/ymin/zmin, u_x = rate t on xmax: uniaxial stress
// at a constant strain rate; a light material so that inertia is negligible.
Model stretched_cube(std::shared_ptr<const MaterialLaw> law, double rate) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::move(law));
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  m.prescribe("xmax", 0, [rate](double t) { return rate * t; });
  return m;
}

}  // namespace

TEST_CASE("cowper-symonds: the solver's dynamic steps pass their time step, static ones do not",
          "[fem][j2][rate]") {
  const double rate = 100.0, eps_y = kSy / kE;
  const double dt = 0.5 * eps_y / rate;
  auto law = std::make_shared<J2PlasticityLaw>(kE, kNu, 1e-3, HardeningCurve::linear(kSy, 0.0),
                                               CowperSymonds(kD, kQ));
  SolverOptions opt;
  opt.newton.force_tolerance = 1e-12;
  SECTION("Newmark (implicit): the steady flow stress, and the reaction at the committed state") {
    // gamma > 1/2 damps the light cube's lateral ringing (omega dt >> 1), which average
    // acceleration would keep
    SolverOptions damped = opt;
    damped.newmark_gamma = 0.9;
    damped.newmark_beta = 0.49;  // (gamma + 1/2)^2 / 4
    StructuralSolver s(stretched_cube(law, rate), damped);
    for (int k = 0; k < 60; ++k) s.step(dt);
    CHECK(std::abs(s.reaction("xmax")[0] - kSy * dynamic_factor(rate)) <= 1e-6 * kSy);
  }
  SECTION("static steps: the rate-independent yield stress") {
    StructuralSolver s(stretched_cube(law, rate), opt);
    for (int k = 0; k < 60; ++k) s.step_static(dt);
    CHECK(std::abs(s.reaction("xmax")[0] - kSy) <= 1e-6 * kSy);
  }
  SECTION("central difference") {
    SolverOptions cd = opt;
    cd.integrator = Integrator::CentralDifference;
    cd.mass = MassType::Lumped;
    StructuralSolver s(stretched_cube(law, rate), cd);
    const double h = std::min(s.stable_time_step(), dt) * 0.5;
    const auto n = static_cast<int>(std::ceil(60 * dt / h));
    for (int k = 0; k < n; ++k) s.step(60 * dt / n);
    CHECK(std::abs(s.reaction("xmax")[0] - kSy * dynamic_factor(rate)) <= 1e-4 * kSy);
  }
}
