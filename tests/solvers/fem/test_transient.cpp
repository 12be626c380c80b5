// Transient validation: cantilever free vibration period vs Euler-Bernoulli, energy
// conservation of undamped average-acceleration Newmark, damping, save/restore.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "fem_test_helpers.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kL = 1.0, kH = 0.05, kE = 210e9, kRho = 7800, kP = 100.0;

// Cantilever, clamped at x = 0, tip load on x = L held for t <= 0 and released afterwards.
Model released_cantilever(ElementType type = ElementType::Hex20) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(kL, kH, kH), {20, 1, 1}, type}),
          Material{kE, 0.3, kRho});
  m.fix("xmin");
  m.add_traction("xmax", Vec3(0, 0, -kP / (kH * kH)),
                 [](double t) { return t <= 0.0 ? 1.0 : 0.0; });
  return m;
}

// first bending period 2 pi / (1.8751^2 sqrt(E I / (rho A L^4)))
double beam_period() {
  const double i = std::pow(kH, 4) / 12.0, a = kH * kH;
  return 2 * std::numbers::pi /
         (1.8751 * 1.8751 * std::sqrt(kE * i / (kRho * a * std::pow(kL, 4))));
}

double tip(const StructuralSolver& s) {
  double sum = 0.0;
  for (auto n : s.mesh().node_set("xmax")) sum += s.displacement(n)[2];
  return sum / static_cast<double>(s.mesh().node_set("xmax").size());
}

// Period from successive upward zero crossings of the tip deflection.
double measured_period(StructuralSolver& s, double dt, int steps) {
  std::vector<double> crossings;
  double prev = tip(s);
  for (int k = 0; k < steps; ++k) {
    s.step(dt);
    const double cur = tip(s);
    if (prev < 0.0 && cur >= 0.0) crossings.push_back(s.time() - dt * cur / (cur - prev));
    prev = cur;
  }
  REQUIRE(crossings.size() >= 2);
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

}  // namespace

TEST_CASE("fem cantilever free vibration: first period vs beam theory", "[fem][transient]") {
  const double t_beam = beam_period();
  for (auto mass : {MassType::Consistent, MassType::Lumped}) {
    SolverOptions opt;
    opt.mass = mass;
    StructuralSolver s(released_cantilever(), opt);
    s.solve_static();
    const double period = measured_period(s, t_beam / 200, 700);
    INFO((mass == MassType::Consistent ? "consistent" : "lumped")
         << " mass: T = " << period << " s, beam theory " << t_beam << " s, error "
         << 100 * (period / t_beam - 1) << " %");
    CHECK(std::abs(period / t_beam - 1) < 0.03);
  }
}

TEST_CASE("fem undamped average-acceleration Newmark conserves energy",
          "[fem][transient][energy]") {
  StructuralSolver s(released_cantilever(ElementType::Hex8));
  s.solve_static();
  const double e0 = s.kinetic_energy() + s.strain_energy() - s.external_work();
  REQUIRE(e0 > 0.0);
  double worst = 0.0, max_kinetic = 0.0;
  for (int k = 0; k < 1000; ++k) {
    s.step(beam_period() / 50);
    const double e = s.kinetic_energy() + s.strain_energy() - s.external_work();
    worst = std::max(worst, std::abs(e - e0) / e0);
    max_kinetic = std::max(max_kinetic, s.kinetic_energy());
  }
  INFO("worst relative energy drift over 1000 steps: " << worst);
  CHECK(worst < 1e-6);
  CHECK(max_kinetic > 0.5 * e0);  // it really vibrates

  SECTION("with a suddenly applied load the balance includes the external work") {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(kL, kH, kH), {10, 1, 1}, ElementType::Hex8}),
            Material{kE, 0.3, kRho});
    m.fix("xmin");
    m.add_traction("xmax", Vec3(0, 0, -kP / (kH * kH)));
    StructuralSolver s2(m);
    double w = 0.0;
    for (int k = 0; k < 200; ++k) {
      s2.step(beam_period() / 50);
      w = std::max(w, s2.external_work());
      const double e = s2.kinetic_energy() + s2.strain_energy() - s2.external_work();
      CHECK(std::abs(e) < 1e-9 * w + 1e-300);
    }
  }
}

TEST_CASE("fem Rayleigh damping dissipates energy", "[fem][transient]") {
  SolverOptions opt;
  opt.rayleigh_alpha = 20.0;
  opt.rayleigh_beta = 1e-5;
  StructuralSolver s(released_cantilever(ElementType::Hex8), opt);
  s.solve_static();
  const double e0 = s.strain_energy();
  double prev = e0;
  for (int k = 0; k < 200; ++k) {
    s.step(beam_period() / 50);
    const double e = s.kinetic_energy() + s.strain_energy();
    CHECK(e <= prev * (1 + 1e-12));
    prev = e;
  }
  CHECK(prev < 0.5 * e0);
}

TEST_CASE("fem save and restore give bit-identical continuations", "[fem][transient][state]") {
  Model m = released_cantilever(ElementType::Hex20);
  m.prescribe("xmin", 0, [](double t) { return 1e-6 * std::sin(1000 * t); });
  StructuralSolver s(m);
  const auto qps = s.face_quadrature_points("zmax");
  MatrixX3 t = MatrixX3::Zero(static_cast<Eigen::Index>(qps.size()), 3);
  t.col(2).setConstant(-1e3);
  s.set_face_tractions_at_quadrature_points("zmax", t);
  const double dt = 1e-4;
  for (int k = 0; k < 5; ++k) s.step(dt);
  const SolverState state = s.save_state();
  std::vector<Eigen::VectorXd> first;
  for (int k = 0; k < 10; ++k) {
    t.col(2).setConstant(-1e3 * (k + 2));
    s.set_face_tractions_at_quadrature_points("zmax", t);
    s.step(dt);
    first.push_back(s.displacement());
  }
  const Eigen::VectorXd v_first = s.velocity();
  s.set_face_tractions_at_quadrature_points("zmax", 5 * t);  // something else, discarded below
  s.restore_state(state);
  CHECK(s.time() == state.time);
  CHECK(s.step_count() == 5);
  for (int k = 0; k < 10; ++k) {
    t.col(2).setConstant(-1e3 * (k + 2));
    s.set_face_tractions_at_quadrature_points("zmax", t);
    s.step(dt);
    CHECK((s.displacement().array() == first[static_cast<std::size_t>(k)].array()).all());
  }
  CHECK((s.velocity().array() == v_first.array()).all());
  // the coupling loads are part of the state
  s.restore_state(state);
  CHECK(s.total_coupling_force()[2] == Approx(-1e3 * kL * kH).epsilon(1e-12));
}

TEST_CASE("fem transient plate oscillates about the static reaction", "[fem][transient][plate]") {
  // The seed plate, load applied suddenly at t = 0 and held: the undamped corner reaction
  // oscillates between ~0 and ~2 p A about p A.
  const double lx = 0.02, lz = 0.002, p = 10e3;
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(lx, lx, lz), {10, 10, 1}, ElementType::Hex8});
  test::add_union_set(mesh, "lateral", {"xmin", "xmax", "ymin", "ymax"});
  mesh.add_node_set_where("corners", [&](const Vec3& x) {
    return x[2] < 1e-9 && (x[0] < 1e-9 || x[0] > lx - 1e-9) && (x[1] < 1e-9 || x[1] > lx - 1e-9);
  });
  Model model(mesh, Material{250e9, 0.3, 7850});
  model.fix("lateral", {0, 1});
  model.fix("corners", {2});
  model.add_pressure("zmax", p);
  StructuralSolver s(model);
  double rmin = 1e300, rmax = -1e300, mean = 0.0;
  const int n = 400;
  for (int k = 0; k < n; ++k) {
    s.step(1e-6);
    const double r = s.reaction("corners")[2];
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
    mean += r / n;
  }
  INFO("corner reaction: min " << rmin << " max " << rmax << " mean " << mean << " N");
  CHECK(rmax > 1.5 * p * lx * lx);
  CHECK(rmax < 2.2 * p * lx * lx);
  CHECK(s.timings().factorisations == 1);  // K_eff once for all steps
}

TEST_CASE("fem steps that differ in the last bits reuse one factorisation", "[fem][transient]") {
  // A coupling advances by t_(k+1) - t_k of absolute times: the sizes differ by rounding only.
  StructuralSolver a(released_cantilever(ElementType::Hex8));
  StructuralSolver b(released_cantilever(ElementType::Hex8));
  const double dt = beam_period() / 50, t0 = 0.3;
  double max_relative_change = 0.0;
  for (int k = 0; k < 200; ++k) {
    const double step = (t0 + (k + 1) * dt) - (t0 + k * dt);
    max_relative_change = std::max(max_relative_change, std::abs(step / dt - 1.0));
    a.step(step);
    b.step(dt);
  }
  INFO("largest relative difference of a step from dt: " << max_relative_change);
  CHECK(max_relative_change > 0.0);  // the sizes did differ
  CHECK(a.timings().factorisations == 1);
  CHECK(std::abs(a.time() - 200 * dt) < 1e-12 * a.time());
  // the same motion: only the clock's rounding differs
  CHECK((a.displacement() - b.displacement()).norm() <= 1e-9 * b.displacement().norm());
  // a really different step size is factorised anew
  a.step(0.5 * dt);
  CHECK(a.timings().factorisations == 2);
}
