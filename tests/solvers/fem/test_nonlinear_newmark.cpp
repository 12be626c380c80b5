// Implicit Newmark on the nonlinear path: energy of an undamped Neo-Hooke bar in free vibration
// at large strain over 40 periods.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

struct EnergyRun {
  double worst = 0.0;          // largest |KE + SE - (W_ext - W_ext,0) - e0| / e0
  double first_periods = 0.0;  // the same over the first 5 periods
  double last_periods = 0.0;   // and over the last 5
  double max_kinetic = 0.0;    // largest KE / e0
};

// Bar 1 x 0.2 x 0.2 m (5 Hex8, rubber E = 2.5 MPa, nu = 0.45), clamped at x = 0, stretched by
// ~15 % under an end traction held for t <= 0 and released: free axial vibration with period
// ~ T = 4 L / c = 84 ms (c = sqrt(E / rho)). `per_period` steps of T / per_period for 40 T.
EnergyRun released_bar(int per_period) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.2, 0.2), {5, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::make_shared<NeoHookeLaw>(2.5e6, 0.45, 1100.0));
  // plain Hex8, as this test was measured with: with the default EAS Hex8 the T/50 run's energy
  // error grows from 1.1 % (first 5 periods) to 3.0 % (last 5) over 40 periods (T/100: 0.5 %,
  // no growth), not yet understood (issue 27)
  m.set_hex8_formulation(Hex8Formulation::Full);
  m.fix("xmin");
  m.add_traction("xmax", Vec3(3.0e5, 0, 0), [](double t) { return t <= 0.0 ? 1.0 : 0.0; });
  SolverOptions opt;
  opt.newton.load_steps = 5;
  opt.newton.force_tolerance = 1e-12;
  StructuralSolver s(std::move(m), opt);
  s.solve_static();
  REQUIRE(s.max_displacement() > 0.1);
  // The scheme's conserved quantity from the release on: KE + SE - (W_ext - W_ext,0), e0 the
  // strain energy at the release (W_ext trapezoidal: half the released load's work in the
  // first step, as the discrete equations see it).
  const double e0 = s.strain_energy(), w0 = s.external_work();
  REQUIRE(e0 > 0.0);
  const double dt = 4.0 / std::sqrt(2.5e6 / 1100.0) / per_period;
  const int steps = 40 * per_period;
  EnergyRun run;
  for (int k = 0; k < steps; ++k) {
    s.step(dt);
    const double err =
        std::abs(s.strain_energy() + s.kinetic_energy() - (s.external_work() - w0) - e0) / e0;
    run.worst = std::max(run.worst, err);
    if (k < 5 * per_period) run.first_periods = std::max(run.first_periods, err);
    if (k >= steps - 5 * per_period) run.last_periods = std::max(run.last_periods, err);
    run.max_kinetic = std::max(run.max_kinetic, s.kinetic_energy() / e0);
  }
  return run;
}

}  // namespace

TEST_CASE("nonlinear Newmark: energy of a Neo-Hooke bar bounded over 40 periods, no drift",
          "[fem][nonlinear][neo-hooke][energy][slow]") {
  // Average acceleration conserves KE + 1/2 u^T K u exactly for a linear system. For a
  // nonlinear one each step replaces int f_int . du by the trapezoidal rule: an error that
  // vanishes at least as dt^2 and, in a conservative oscillation, cancels over a period
  // instead of accumulating: bounded, no drift.
  const EnergyRun coarse = released_bar(50), fine = released_bar(100);
  INFO("T/50: worst " << coarse.worst << " (first 5 periods " << coarse.first_periods << ", last 5 "
                      << coarse.last_periods << "); T/100: worst " << fine.worst << " (first "
                      << fine.first_periods << ", last " << fine.last_periods << ")");
  CHECK(fine.worst < 1e-2);
  CHECK(coarse.worst / fine.worst > 4.0);  // a discretisation error of order >= 2
  for (const EnergyRun& r : {coarse, fine}) {
    CHECK(r.last_periods < 1.5 * r.first_periods);  // no drift over 40 periods (2000-4000 steps)
    CHECK(r.max_kinetic > 0.5);                     // it really vibrates
  }
}
