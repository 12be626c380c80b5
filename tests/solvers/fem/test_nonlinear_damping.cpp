// Rayleigh damping C = alpha M + beta K0 on the nonlinear path (Newmark with Newton, central
// difference): the free vibration of a one-mode Neo-Hooke column decays with the logarithmic
// decrement of xi = alpha / (2 omega) + beta omega / 2, the damping work closes the energy
// balance, and beta lowers the explicit stable step to (2/omega)(sqrt(1 + xi^2) - xi).
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <vector>

#include "fem_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 2.5e6, kNu = 0.3, kRho = 1100.0, kL = 0.01;
constexpr double kPi = 3.14159265358979323846;

// One Hex8 cube of side L: x and y held everywhere, z held on the bottom face, so the four
// top nodes move in z only. A uniform load on the top excites only the uniform mode (uniaxial
// strain, u_z = u z / L, exact in the element): stiffness (lambda + 2 mu) A / L, mass of the
// top nodes rho A L / 3 (consistent) or rho A L / 2 (lumped), so
// omega^2 = 3 (lambda + 2 mu) / (rho L^2) or 2 (lambda + 2 mu) / (rho L^2).
// Released at t = 0 from the static state under a pressure giving a strain of 1e-4: at that
// amplitude the Neo-Hooke column is linear to ~1e-4 (its tangent at rest is the elastic one).
Model column() {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(kL, kL, kL), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::make_shared<NeoHookeLaw>(kE, kNu, kRho));
  m.fix("all", {0, 1});
  m.fix("zmin", {2});
  const double lambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu)), mu = kE / (2 * (1 + kNu));
  m.add_pressure("zmax", 1e-4 * (lambda + 2 * mu), [](double t) { return t <= 0.0 ? 1.0 : 0.0; });
  return m;
}

double omega(MassType mass) {
  const double lambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu)), mu = kE / (2 * (1 + kNu));
  return std::sqrt((mass == MassType::Lumped ? 2.0 : 3.0) * (lambda + 2 * mu) / (kRho * kL * kL));
}

struct DecayRun {
  double decrement = 0.0;      // ln(first peak / last peak) / periods between them
  int periods = 0;             // peaks - 1
  double energy_error = 0.0;   // largest |KE + SE + W_d - (W_ext - W_ext,0) - e0| / e0
  double damping_share = 0.0;  // W_d / e0 at the end
};

// Steps `steps` of dt from the released static state; the decrement from the positive peaks
// of the top displacement (each peak located by a parabola through the three samples).
DecayRun decay(SolverOptions opt, double dt, int steps) {
  StructuralSolver s(column(), opt);
  s.solve_static();
  const auto top = s.mesh().node_set("zmax");
  const auto dof = 3 * static_cast<Eigen::Index>(top[0]) + 2;
  // energy at the release; the work of the loads counts from there (the static solve's own
  // external work is what the strain energy stores)
  const double e0 = s.strain_energy(), w0 = s.external_work();
  REQUIRE(e0 > 0.0);
  DecayRun run;
  std::vector<double> u{-s.displacement()[dof]}, peaks;
  for (int k = 0; k < steps; ++k) {
    s.step(dt);
    u.push_back(-s.displacement()[dof]);  // compression positive
    const double e =
        s.strain_energy() + s.kinetic_energy() + s.damping_work() - (s.external_work() - w0);
    run.energy_error = std::max(run.energy_error, std::abs(e - e0) / e0);
    const std::size_t n = u.size();
    if (n >= 3 && u[n - 2] > 0 && u[n - 2] >= u[n - 3] && u[n - 2] > u[n - 1]) {
      // vertex of the parabola through (-1, a), (0, b), (1, c): b + (a - c)^2 / (8 (2b - a - c))
      const double a = u[n - 3], b = u[n - 2], c = u[n - 1];
      peaks.push_back(b + (a - c) * (a - c) / (8.0 * (2.0 * b - a - c)));
    }
  }
  run.periods = static_cast<int>(peaks.size()) - 1;
  if (run.periods > 0) run.decrement = std::log(peaks.front() / peaks.back()) / run.periods;
  run.damping_share = s.damping_work() / e0;
  return run;
}

double expected_decrement(double xi) {
  return 2.0 * kPi * xi / std::sqrt(1.0 - xi * xi);
}

}  // namespace

TEST_CASE("nonlinear Newmark damping: the decrement of xi = alpha/(2 omega) + beta omega/2",
          "[fem][nonlinear][damping]") {
  const double w = omega(MassType::Consistent);
  const double dt = 2.0 * kPi / w / 200.0;  // 200 steps per period
  const double xi = 0.05;
  // {alpha, beta}: all of xi from the mass part, all from the stiffness part, half each
  const std::vector<std::pair<double, double>> cases = {
      {2.0 * w * xi, 0.0}, {0.0, 2.0 * xi / w}, {w * xi, xi / w}};
  for (const auto& [alpha, beta] : cases) {
    SolverOptions opt;
    opt.rayleigh_alpha = alpha;
    opt.rayleigh_beta = beta;
    opt.newton.force_tolerance = 1e-12;
    const DecayRun run = decay(opt, dt, 1050);  // 5 periods after the release: 5 peaks
    INFO("alpha " << alpha << " 1/s, beta " << beta << " s: decrement " << run.decrement << " over "
                  << run.periods << " periods, expected " << expected_decrement(xi)
                  << "; energy error " << run.energy_error << ", damping work / e0 "
                  << run.damping_share);
    REQUIRE(run.periods >= 4);
    // Average acceleration has no algorithmic damping; its period error (omega dt)^2 / 12
    // ~ 1e-4 and the Neo-Hooke nonlinearity at strain 1e-4 are far inside 1 %.
    CHECK(run.decrement == Approx(expected_decrement(xi)).epsilon(0.01));
    // The damping work dt v_mid . C v_mid is exact for average acceleration, so the balance
    // holds to the trapezoidal error of the nonlinear strain energy (strain 1e-4: ~1e-8).
    CHECK(run.energy_error < 1e-6);
    CHECK(run.damping_share > 0.8);  // after 5 periods at xi = 0.05, 96 % is dissipated
  }
}

TEST_CASE("central difference with damping: the decrement, the energy balance, the stable step",
          "[fem][nonlinear][damping][explicit]") {
  SolverOptions opt;
  opt.mass = MassType::Lumped;
  opt.integrator = Integrator::CentralDifference;
  const double w = omega(MassType::Lumped);
  const double xi = 0.05;
  opt.rayleigh_alpha = w * xi;
  opt.rayleigh_beta = xi / w;
  const double dt = 2.0 * kPi / w / 400.0;
  const DecayRun run = decay(opt, dt, 2050);
  INFO("decrement " << run.decrement << " over " << run.periods << " periods, expected "
                    << expected_decrement(xi) << "; energy error " << run.energy_error);
  REQUIRE(run.periods >= 4);
  // The stiffness-proportional force is lagged by half a step: an error of order omega dt / 2
  // ~ 0.8 % in its share of the decrement; 2 % bounds it.
  CHECK(run.decrement == Approx(expected_decrement(xi)).epsilon(0.02));
  // Central differences conserve a modified energy: the plain one oscillates by about
  // (omega dt)^2 / 8 ~ 3e-5; the damping work of the lagged force adds O(xi omega dt) ~ 1e-3.
  CHECK(run.energy_error < 5e-3);

  SECTION("beta lowers stable_time_step() by sqrt(1 + xi^2) - xi at omega_max") {
    SolverOptions undamped = opt;
    undamped.rayleigh_alpha = undamped.rayleigh_beta = 0.0;
    const double dt0 = StructuralSolver(column(), undamped).stable_time_step();
    SolverOptions stiff = undamped;
    stiff.rayleigh_beta = 0.5 * dt0;  // xi_max = beta omega_max / 2 = 0.5
    const double dt1 = StructuralSolver(column(), stiff).stable_time_step();
    CHECK(dt1 / dt0 == Approx(std::sqrt(1.25) - 0.5).epsilon(1e-12));
  }
}

TEST_CASE("central difference with stiffness damping: the observed limit is the bound",
          "[fem][damping][explicit]") {
  // The rod of test_explicit.cpp (20 Hex8 in uniaxial strain along x, lumped mass), for which
  // the element bound is the exact limit h / c_d; with beta = 0.3 h / c_d (xi_max = 0.3) the
  // 1D limit of the lagged scheme is (2 / omega_max)(sqrt(1 + xi^2) - xi): 0.74 of the undamped.
  auto rod = [] {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(0.2, 0.01, 0.01), {20, 1, 1}, ElementType::Hex8}));
    m.set_material_law(std::make_shared<NeoHookeLaw>(210e9, 0.3, 7800.0));
    m.fix("all", {1, 2});
    m.fix("xmin", {0});
    return m;
  };
  SolverOptions opt;
  opt.mass = MassType::Lumped;
  opt.integrator = Integrator::CentralDifference;
  const double undamped = StructuralSolver(rod(), opt).stable_time_step();
  opt.rayleigh_beta = 0.3 * undamped;
  const double estimate = StructuralSolver(rod(), opt).stable_time_step();
  const double xi = 0.5 * opt.rayleigh_beta * 2.0 / undamped;
  CHECK(estimate == Approx(undamped * (std::sqrt(1 + xi * xi) - xi)).epsilon(1e-12));
  // grows (unstable) or stays bounded over 400 steps from random initial accelerations
  auto grows = [&](double dt) {
    StructuralSolver s(rod(), opt);
    return test::axial_kick_grows(s, dt, 400);
  };
  auto unstable = [&](double dt) {
    try {
      return grows(dt);
    } catch (const Error&) {
      return true;  // an element inverted: it grew
    }
  };
  double lo = 0.5 * estimate, hi = 2.0 * estimate;
  REQUIRE(!unstable(lo));
  REQUIRE(unstable(hi));
  for (int i = 0; i < 20; ++i) {
    const double mid = 0.5 * (lo + hi);
    (unstable(mid) ? hi : lo) = mid;
  }
  INFO("observed limit " << lo << " s, estimate " << estimate << " s, undamped " << undamped);
  CHECK(estimate <= hi);                        // not above the observed limit
  CHECK(std::abs(estimate - lo) <= 0.05 * lo);  // and the bound is sharp here
  CHECK(lo < 0.9 * undamped);                   // damping really lowered the limit
}
