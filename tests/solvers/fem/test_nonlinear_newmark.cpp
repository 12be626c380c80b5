// Implicit Newmark on the nonlinear path: energy of an undamped Neo-Hooke bar in free vibration
// at large strain over 120 periods.
#include <catch2/catch.hpp>
#include <cmath>
#include <algorithm>
#include <memory>
#include <vector>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

struct EnergyRun {
  // largest |KE + SE - (W_ext - W_ext,0) - e0| / e0 in each period
  std::vector<double> period_worst;
  double max_kinetic = 0.0;  // largest KE / e0
  // the largest error over periods [first, end)
  double worst(std::size_t first, std::size_t end) const {
    return *std::max_element(period_worst.begin() + static_cast<std::ptrdiff_t>(first),
                             period_worst.begin() + static_cast<std::ptrdiff_t>(end));
  }
};

// Bar 1 x 0.2 x 0.2 m (5 Hex8, rubber E = 2.5 MPa, nu = 0.45), clamped at x = 0, stretched by
// ~15 % under an end traction held for t <= 0 and released: free axial vibration with period
// ~ T = 4 L / c = 84 ms (c = sqrt(E / rho)). `per_period` steps of T / per_period for
// `periods` T. The default Hex8 of the nonlinear path (EAS).
EnergyRun released_bar(int per_period, int periods) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.2, 0.2), {5, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::make_shared<NeoHookeLaw>(2.5e6, 0.45, 1100.0));
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
  EnergyRun run;
  for (int k = 0; k < periods * per_period; ++k) {
    s.step(dt);
    const double err =
        std::abs(s.strain_energy() + s.kinetic_energy() - (s.external_work() - w0) - e0) / e0;
    if (k % per_period == 0) run.period_worst.push_back(0.0);
    run.period_worst.back() = std::max(run.period_worst.back(), err);
    run.max_kinetic = std::max(run.max_kinetic, s.kinetic_energy() / e0);
  }
  return run;
}

}  // namespace

TEST_CASE("nonlinear Newmark: energy of a Neo-Hooke bar bounded over 120 periods, no drift",
          "[fem][nonlinear][neo-hooke][energy][slow]") {
  // Average acceleration conserves KE + 1/2 u^T K u exactly for a linear system. For a
  // nonlinear one each step replaces int f_int . du by the trapezoidal rule: an error that
  // vanishes at least as dt^2 and, in a conservative oscillation, cancels over a period
  // instead of accumulating: bounded, no drift. Bounded, not constant: the bar's modes exchange
  // energy slowly (the large strain couples them), and the error, larger in the higher modes,
  // beats with them over ~100 periods. With the EAS Hex8 at T/50 the largest error per period
  // rises from 0.8 % to 2.9 % around period 45 and falls back to 1.0-1.4 % by period 120 (plain
  // Hex8: between 1.6 % and 4.0 %); a window of 40 periods saw only the rise (1.1 % in the
  // first 5, 3.0 % in the last 5), which read as a drift. So: no drift means the last 40 of 120
  // periods no worse than the first 40.
  const EnergyRun coarse = released_bar(50, 120), fine = released_bar(100, 40);
  const double coarse40 = coarse.worst(0, 40), fine40 = fine.worst(0, 40);
  INFO("T/50: worst over periods 0-40 " << coarse40 << ", 80-120 " << coarse.worst(80, 120)
                                        << "; T/100: worst over 0-40 " << fine40);
  CHECK(fine40 < 1e-2);
  CHECK(coarse40 / fine40 > 4.0);  // a discretisation error of order >= 2
  CHECK(coarse.worst(80, 120) < 1.5 * coarse40);  // no drift over 120 periods (6000 steps)
  CHECK(coarse.max_kinetic > 0.5);                 // it really vibrates
  CHECK(fine.max_kinetic > 0.5);
}
