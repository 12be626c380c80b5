// Rupture by the damage criteria of ship-collision analysis: RTCL (Rice-Tracey /
// Cockcroft-Latham, D = int f(T) d eps_p / eps_cr by the stress triaxiality T) and BWH
// (Bressan-Williams-Hill local necking limit of the in-plane stresses), each point's damage in
// the committed state, the element failing when its mean damage reaches 1.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/failure_criterion.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6, kH = 1e9;

// One Hex8 of a plate, 0.1 x 0.1 x 0.01 m, held by its three symmetry planes; its x and y faces
// moved by ex(t) and ey(t) times the size (nullptr: free): a homogeneous plane-stress state.
StructuralSolver plate_cell(const FailureCriterion& c, std::function<double(double)> ex,
                            std::function<double(double)> ey) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(0.1, 0.1, 0.01), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kH)));
  m.set_failure_criterion(c);
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  if (ex) m.prescribe("xmax", 0, [ex](double t) { return 0.1 * ex(t); });
  if (ey) m.prescribe("ymax", 1, [ey](double t) { return 0.1 * ey(t); });
  return StructuralSolver(std::move(m));
}

struct Failure {
  std::optional<FailureEvent> event;
  double plastic_strain_before = 0.0;  // the element's mean eps_p at the step before it failed
  double damage_before = 0.0;
};

// static steps of dt (strain rate 1 / s: dt is the strain step) until the element fails or
// t_end
Failure run_to_failure(StructuralSolver& s, double dt, double t_end) {
  Failure f;
  while (s.failed_elements() == 0 && s.time() < t_end) {
    f.plastic_strain_before = s.element_equivalent_plastic_strain()[0];
    f.damage_before = s.element_damage(0);
    s.step_static(dt);
  }
  f.event = s.first_failure();
  return f;
}

}  // namespace

TEST_CASE("rupture: RTCL's triaxiality weight, both branches 1 in uniaxial tension",
          "[fem][rupture]") {
  // Cockcroft-Latham (sigma_1 / sigma_eq in plane stress) below T = 1/3, Rice-Tracey's
  // exp(3/2 T) above, normalised to 1 at T = 1/3; nothing at T <= -1/3
  CHECK(rtcl_weight(1.0 / 3.0) == Approx(1.0).epsilon(1e-14));
  CHECK(rtcl_weight(1.0 / 3.0 - 1e-9) == Approx(1.0).epsilon(1e-8));
  CHECK(rtcl_weight(0.0) == Approx(1.0 / std::sqrt(3.0)).epsilon(1e-14));  // pure shear
  CHECK(rtcl_weight(2.0 / 3.0) == Approx(std::exp(0.5)).epsilon(1e-14));   // equibiaxial
  CHECK(rtcl_weight(-1.0 / 3.0) == 0.0);
  CHECK(rtcl_weight(-1.0 / 3.0 + 1e-9) == Approx(0.0).margin(1e-8));  // continuous there
  CHECK(rtcl_weight(-2.0 / 3.0) == 0.0);
  // plane stress sigma = (1, a, 0): the Cockcroft-Latham branch is sigma_1 / sigma_eq
  for (double a : {-0.9, -0.5, -0.2, 0.0}) {
    const double eq = std::sqrt(1.0 - a + a * a), t = (1.0 + a) / 3.0 / eq;
    CHECK(rtcl_weight(t) == Approx(1.0 / eq).epsilon(1e-12));
  }
}

TEST_CASE("rupture: RTCL fails at eps_cr / f(T) in tension, equibiaxial tension and shear",
          "[fem][rupture]") {
  // proportional plane-stress paths: T is constant, so D = f(T) eps_p / eps_cr and the element
  // fails at the step where eps_p crosses eps_cr / f(T): eps_cr (T = 1/3), eps_cr / e^(1/2)
  // (T = 2/3), sqrt(3) eps_cr (T = 0)
  const double eps_cr = 0.1, dt = 1e-4;
  const auto ramp = [](double t) { return t; };
  const auto reverse = [](double t) { return -t; };
  struct Path {
    const char* name;
    std::function<double(double)> ex, ey;
    double expected;
  };
  for (const Path& p : {Path{"uniaxial", ramp, nullptr, eps_cr},
                        Path{"equibiaxial", ramp, ramp, eps_cr / std::exp(0.5)},
                        Path{"pure shear", ramp, reverse, std::sqrt(3.0) * eps_cr}}) {
    INFO(p.name);
    StructuralSolver s = plate_cell(FailureCriterion::rtcl(eps_cr), p.ex, p.ey);
    const Failure f = run_to_failure(s, dt, 1.0);
    REQUIRE(f.event.has_value());
    CHECK(f.event->damage >= 1.0);
    CHECK(f.damage_before < 1.0);
    // in the step that crosses it (a step's equivalent strain: dt uniaxial, 2 / sqrt(3) dt in
    // shear, 2 dt equibiaxial)
    CHECK(f.plastic_strain_before < p.expected * (1.0 + 1e-9));
    CHECK(f.event->plastic_strain >= p.expected * (1.0 - 1e-9));
    CHECK(f.event->plastic_strain < p.expected + 2.0 * dt);
    CHECK(f.event->failure_strain == eps_cr);
  }
}

TEST_CASE("rupture: RTCL never fails under compression, and its damage is restarted",
          "[fem][rupture]") {
  const auto press = [](double t) { return -t; };
  // equibiaxial compression (T = -2/3) to 5 times eps_cr: no damage at all
  StructuralSolver s = plate_cell(FailureCriterion::rtcl(0.05), press, press);
  for (int k = 0; k < 50; ++k) s.step_static(5e-3);
  CHECK(s.element_equivalent_plastic_strain()[0] > 0.2);
  CHECK(s.failed_elements() == 0);
  CHECK(s.element_damage(0) == 0.0);
  // uniaxial tension: the damage (in the committed state) survives a save and restore
  const auto pull = [](double t) { return t; };
  StructuralSolver a = plate_cell(FailureCriterion::rtcl(0.05), pull, nullptr);
  for (int k = 0; k < 30; ++k) a.step_static(1e-3);
  const double damage = a.element_damage(0);
  CHECK(damage > 0.3);
  CHECK(damage < 1.0);
  const SolverState saved = a.save_state();
  StructuralSolver b = plate_cell(FailureCriterion::rtcl(0.05), pull, nullptr);
  b.restore_state(saved);
  CHECK(b.element_damage(0) == damage);
  const Failure fa = run_to_failure(a, 1e-3, 1.0), fb = run_to_failure(b, 1e-3, 1.0);
  REQUIRE(fa.event.has_value());
  REQUIRE(fb.event.has_value());
  CHECK(fb.event->time == fa.event->time);
  CHECK(fb.event->damage == fa.event->damage);
}

TEST_CASE("rupture: the size scaling of RTCL's eps_cr and BWH's critical thickness strain",
          "[fem][rupture]") {
  // n + (eps_n - n) t / l_e: eps_n where l_e = t, tending to n for long elements
  const auto rtcl = FailureCriterion::rtcl_scaled(0.01, 0.2, 0.8);
  CHECK(rtcl.failure_strain(0.01) == Approx(0.8).epsilon(1e-14));
  CHECK(rtcl.failure_strain(0.05) == Approx(0.2 + 0.6 * 0.2).epsilon(1e-14));
  CHECK(rtcl.failure_strain(1e6) == Approx(0.2).epsilon(1e-6));
  const auto bwh = FailureCriterion::bwh(530e6, 0.2, 0.01, 0.8);
  CHECK(bwh.failure_strain(0.05) == Approx(0.2 + 0.6 * 0.2).epsilon(1e-14));
  CHECK(FailureCriterion::bwh(530e6, 0.2).failure_strain(0.05) == 0.2);  // unscaled: n
  CHECK(FailureCriterion::rtcl(0.3).failure_strain(0.05) == 0.3);
  CHECK_THROWS_WITH(FailureCriterion::rtcl(0.0), Catch::Contains("critical strain"));
  CHECK_THROWS_WITH(FailureCriterion::rtcl_scaled(0.01, 1.2, 0.8), Catch::Contains("(0, 1)"));
  CHECK_THROWS_WITH(FailureCriterion::rtcl_scaled(0.01, 0.2, 0.1), Catch::Contains("neck strain"));
  CHECK_THROWS_WITH(FailureCriterion::bwh(0.0, 0.2), Catch::Contains("strength coefficient"));
  CHECK_THROWS_WITH(FailureCriterion::bwh(530e6, 0.2, 0.0, 0.8), Catch::Contains("thickness"));
}

TEST_CASE("rupture: the BWH limit stress against Hill's and Bressan-Williams' closed forms",
          "[fem][rupture]") {
  const double k = 530e6, n = 0.2;
  // uniaxial (alpha = 0, beta = -1/2): Hill's neck at eps_1 = n / (1 + beta) = 2n, where
  // sigma_1 = sigma_eq = K (2n)^n
  CHECK(bwh_limit_stress(0.0, k, n, n) == Approx(k * std::pow(2.0 * n, n)).epsilon(1e-13));
  // plane strain (alpha = 1/2, beta = 0): eps_1 = n, eps_eq = (2 / sqrt 3) n and
  // sigma_1 = (2 / sqrt 3) sigma_eq; the two branches meet there
  const double plane = 2.0 / std::sqrt(3.0) * k * std::pow(2.0 / std::sqrt(3.0) * n, n);
  CHECK(bwh_limit_stress(0.5, k, n, n) == Approx(plane).epsilon(1e-13));
  CHECK(bwh_limit_stress(0.5 + 1e-9, k, n, n) == Approx(plane).epsilon(1e-8));
  // equibiaxial (beta = 1): Bressan-Williams' shear plane at sin^2 = 1 / (2 + beta), the
  // through-thickness shear stress sigma_1 sqrt(1 + beta) / (2 + beta) that of plane strain
  CHECK(bwh_limit_stress(1.0, k, n, n) == Approx(plane * 3.0 / (2.0 * std::sqrt(2.0))).epsilon(1e-13));
  // alpha = -1/2 (beta = -4/5): Hill, eps_eq = (2 / sqrt 3) n sqrt(beta^2 + beta + 1) / (1 + beta),
  // sigma_1 = sigma_eq / sqrt(1 - alpha + alpha^2)
  {
    const double a = -0.5, b = (2.0 * a - 1.0) / (2.0 - a);
    const double eps_eq = 2.0 / std::sqrt(3.0) * n * std::sqrt(b * b + b + 1.0) / (1.0 + b);
    CHECK(bwh_limit_stress(a, k, n, n) ==
          Approx(k * std::pow(eps_eq, n) / std::sqrt(1.0 - a + a * a)).epsilon(1e-13));
  }
  // in-plane shear and beyond: no local neck
  CHECK(std::isinf(bwh_limit_stress(-1.0, k, n, n)));
  CHECK(std::isinf(bwh_limit_stress(-3.0, k, n, n)));
}

TEST_CASE("rupture: BWH fails a plate cell when its major stress reaches the limit",
          "[fem][rupture]") {
  // linear hardening: sigma_1 = sigma_eq = sigma_y + H eps_p in uniaxial and equibiaxial plane
  // stress, so the element fails in the step where eps_p crosses (sigma_1* - sigma_y) / H
  const double k = 530e6, n = 0.2, dt = 1e-4;
  const auto ramp = [](double t) { return t; };
  struct Path {
    const char* name;
    std::function<double(double)> ey;
    double alpha;
  };
  for (const Path& p : {Path{"uniaxial", nullptr, 0.0}, Path{"equibiaxial", ramp, 1.0}}) {
    INFO(p.name);
    const double eps_f = (bwh_limit_stress(p.alpha, k, n, n) - kSy) / kH;
    StructuralSolver s = plate_cell(FailureCriterion::bwh(k, n), ramp, p.ey);
    const Failure f = run_to_failure(s, dt, 1.0);
    REQUIRE(f.event.has_value());
    CHECK(f.event->damage >= 1.0);
    CHECK(f.damage_before < 1.0);
    CHECK(f.plastic_strain_before < eps_f * (1.0 + 1e-9));
    CHECK(f.event->plastic_strain >= eps_f * (1.0 - 1e-9));
    CHECK(f.event->plastic_strain < eps_f + 2.0 * dt);  // a step's eps_p: at most 2 dt
  }
  // in-plane shear (alpha = -1) never necks
  StructuralSolver shear = plate_cell(FailureCriterion::bwh(k, n), ramp, [](double t) { return -t; });
  for (int k2 = 0; k2 < 40; ++k2) shear.step_static(1e-2);
  CHECK(shear.failed_elements() == 0);
  CHECK(shear.element_equivalent_plastic_strain()[0] > 0.3);
  // BWH is a plate criterion: a tetrahedral part is refused
  Model tets(make_box_mesh({Vec3::Zero(), Vec3(0.1, 0.1, 0.01), {1, 1, 1}, ElementType::Tet4}));
  tets.set_material_law(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kH)));
  tets.set_failure_criterion(FailureCriterion::bwh(k, n));
  tets.fix("xmin", {0, 1, 2});
  CHECK_THROWS_WITH(StructuralSolver(std::move(tets)), Catch::Contains("hexahedral"));
}

TEST_CASE("rupture: BWH reads the in-plane state with the deviator of the 3D stress",
          "[fem][rupture]") {
  // the criterion is a plane-stress forming limit: a stress through the thickness shifts the
  // in-plane stresses it sees (J2 flow, and so the strain path, depend on the deviator alone)
  const double k = 530e6, n = 0.2;
  const FailureCriterion c = FailureCriterion::bwh(k, n);
  const double crit = c.failure_strain(0.0);
  const Vec3 normal = Vec3(1.0, 2.0, 2.0) / 3.0;  // a plate that is not aligned with the axes
  const Vec3 helper = Vec3::UnitX();
  const Vec3 a = normal.cross(helper).normalized(), b = normal.cross(a);
  auto state = [&](double s_a, double s_b, double s_ab, double s_n) {
    return Mat3(s_a * a * a.transpose() + s_b * b * b.transpose() +
                s_ab * (a * b.transpose() + b * a.transpose()) + s_n * normal * normal.transpose());
  };
  const double d_eps = 1e-3;
  // uniaxial in-plane tension at 90 % of the limit: D = 0.9
  const double limit = bwh_limit_stress(0.0, k, n, crit);
  const double plane = c.updated_damage(0.0, state(0.9 * limit, 0.0, 0.0, 0.0), d_eps, crit, normal);
  CHECK(plane == Approx(0.9).epsilon(1e-12));
  // a hydrostatic stress added (tension or pressure) changes nothing
  for (const double p : {-400e6, 250e6}) {
    const Mat3 s = state(0.9 * limit, 0.0, 0.0, 0.0) + p * Mat3::Identity();
    CHECK(c.updated_damage(0.0, s, d_eps, crit, normal) == Approx(plane).epsilon(1e-12));
  }
  // a tension through the thickness (a web pulling on the plate) with the same in-plane stresses
  // is less in-plane tension: sigma_1 = 0.9 limit - 0.3 limit, sigma_2 = -0.3 limit
  {
    const double s1 = 0.6 * limit, s2 = -0.3 * limit;
    const double expect = s1 / bwh_limit_stress(s2 / s1, k, n, crit);
    CHECK(c.updated_damage(0.0, state(0.9 * limit, 0.0, 0.0, 0.3 * limit), d_eps, crit, normal) ==
          Approx(expect).epsilon(1e-12));
  }
  // a pressure through the thickness alone is equibiaxial in-plane tension to the criterion
  // (the plate thins as under equibiaxial stretching)
  {
    const double q = 0.5 * limit;
    const double expect = q / bwh_limit_stress(1.0, k, n, crit);
    CHECK(c.updated_damage(0.0, state(0.0, 0.0, 0.0, -q), d_eps, crit, normal) ==
          Approx(expect).epsilon(1e-12));
  }
  // in-plane shear, with or without a hydrostatic stress, keeps alpha = -1: no neck
  CHECK(c.updated_damage(0.0, state(0.0, 0.0, 300e6, 0.0), d_eps, crit, normal) == 0.0);
  CHECK(c.updated_damage(0.0, state(200e6, 200e6, 300e6, 200e6), d_eps, crit, normal) == 0.0);
}
