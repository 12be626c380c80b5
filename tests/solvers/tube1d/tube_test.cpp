// The 1D elastic tube alone: tube law, discrete mass conservation, steady flow.
#include <catch2/catch.hpp>

#include <cmath>

#include "partita/tube1d/tube_flow.hpp"
#include "partita/tube1d/tube_wall.hpp"

using namespace partita::tube1d;

TEST_CASE(
    "Tube law: a(p) and p(a) are inverse, dp/da at a0 gives the wave speed c^2 = E / (2 rho r0)",
    "[tube1d]") {
  TubeParameters prm;
  prm.density = 1.3;
  TubeWall wall(prm);
  for (double a : {0.8, 1.0, 1.05, 1.7})
    CHECK(wall.area_of(wall.pressure_of(a)) == Approx(a).epsilon(1e-13));
  CHECK(wall.area_of(prm.reference_pressure) == Approx(prm.reference_area).epsilon(1e-15));
  // Moens-Korteweg: c^2 = (a / rho) dp/da at the reference state
  const double h = 1e-6;
  const double dpda = (wall.pressure_of(1.0 + h) - wall.pressure_of(1.0 - h)) / (2 * h);
  CHECK(prm.reference_area / prm.density * dpda == Approx(prm.wave_speed_squared()).epsilon(1e-8));
  CHECK(prm.wave_speed_squared() == Approx(10000.0 * std::sqrt(M_PI) / 2.0 / 1.3).epsilon(1e-14));
  // the wall follows the pressure at each step
  wall.set_pressure(Eigen::VectorXd::LinSpaced(prm.cells + 1, 0.0, 100.0));
  wall.advance(0.01);
  CHECK(wall.area()(prm.cells) == Approx(wall.area_of(100.0)).epsilon(1e-15));
  CHECK(wall.area()(prm.cells) > 1.0);  // pressure widens the tube
}

TEST_CASE("Tube flow conserves mass: the area change balances the face fluxes", "[tube1d]") {
  // sum_{i=1}^{N-1} (a_i^{n+1} - a_i^n) dx / dt = F_{1/2} - F_{N-1/2}, telescoped from the
  // continuity equations (a prescribed, moving wall).
  TubeParameters prm;
  TubeFlow flow(prm);
  const int n = prm.cells + 1;
  const double dt = 0.01;
  for (int step = 1; step <= 5; ++step) {
    const Eigen::VectorXd a_old = flow.area();
    Eigen::VectorXd a(n);
    for (int i = 0; i < n; ++i) a(i) = 1.0 + 0.02 * step * std::sin(M_PI * i / prm.cells);
    flow.set_area(a);
    flow.advance(dt);
    double storage = 0.0;
    for (int i = 1; i < prm.cells; ++i) storage += (a(i) - a_old(i)) * prm.dx() / dt;
    const double net_in = flow.face_flux(0) - flow.face_flux(prm.cells - 1);
    INFO("step " << step << ": storage " << storage << ", net inflow " << net_in);
    CHECK(storage == Approx(net_in).margin(1e-9 * flow.face_flux(0)));
    CHECK(std::abs(storage) > 0.1);  // the check is not trivial
  }
}

TEST_CASE("Tube flow reaches a steady state in a rigid narrowing tube: uniform flux, Bernoulli",
          "[tube1d]") {
  // Steady inflow u = 10 through a rigid tube with a throat a = 0.8 at mid-length.
  auto steady = [](int cells) {
    TubeParameters prm;
    prm.cells = cells;
    prm.inlet_amplitude = 0.0;
    TubeFlow flow(prm);
    Eigen::VectorXd a(cells + 1);
    for (int i = 0; i <= cells; ++i) a(i) = 1.0 - 0.2 * std::sin(M_PI * i / cells);
    for (int step = 0; step < 400; ++step) {
      flow.set_area(a);
      flow.advance(0.01);
    }
    return flow;
  };
  const TubeFlow flow = steady(100);
  const int N = flow.parameters().cells;
  // mass: the flux a u is the same through every face
  double fmin = 1e300, fmax = -1e300;
  for (int i = 0; i < N; ++i) {
    fmin = std::min(fmin, flow.face_flux(i));
    fmax = std::max(fmax, flow.face_flux(i));
  }
  CHECK((fmax - fmin) < 1e-8 * fmax);
  CHECK(flow.velocity()(0) == Approx(10.0).epsilon(1e-14));
  // the throat: velocity 10 / 0.8 = 12.5 (up to the face averaging)
  CHECK(flow.velocity()(N / 2) == Approx(12.5).epsilon(2e-3));
  // momentum: the head p + rho u^2 / 2 is constant along the tube (Bernoulli) up to the
  // discretisation error, which is first order in dx: halving dx halves the defect.
  auto head_range = [](const TubeFlow& f) {
    const Eigen::VectorXd h =
        f.pressure().array() + 0.5 * f.parameters().density * f.velocity().array().square();
    return h.maxCoeff() - h.minCoeff();
  };
  const double swing =
      flow.pressure().maxCoeff() - flow.pressure().minCoeff();  // ~ rho (12.5^2 - 10^2) / 2
  CHECK(swing == Approx(0.5 * (12.5 * 12.5 - 100.0)).epsilon(0.05));
  const double d100 = head_range(flow), d200 = head_range(steady(200));
  INFO("head defect: N = 100 " << d100 << ", N = 200 " << d200 << " (pressure swing " << swing
                               << ")");
  CHECK(d100 < 0.05 * swing);
  CHECK(d200 / d100 == Approx(0.5).margin(0.05));
}
