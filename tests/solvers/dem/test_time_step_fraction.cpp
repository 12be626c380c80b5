// The time step chosen from the restitution realises it to 1 % (a fixed 0.2 of the Rayleigh
// step would make the calibrated e = 0.1 several per cent low), impacts from 0.01 to 10 m/s.

#include "dem_test_helpers.hpp"

#include "partita/dem/restitution_calibration.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace partita::dem;

namespace {

// Realised restitution: relative normal speed after / before a head-on impact of two equal
// spheres (or a sphere on a plane), no friction, no gravity, at dt = fraction x Rayleigh step.
double realised(double e, double v, bool wall, double fraction = -1.0) {
  const double r = 1e-3;
  System sys = test::single_material(1e9, 0.3, 2500.0, e, 0.0);
  if (wall) {
    sys.add_particle({0, 0, r}, r, 0, {0, 0, -v});
    sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  } else {
    sys.add_particle({-r, 0, 0}, r, 0, {0.5 * v, 0, 0});
    sys.add_particle({r, 0, 0}, r, 0, {-0.5 * v, 0, 0});
  }
  const double f = fraction > 0.0 ? fraction : sys.time_step_fraction();
  const double dt = f * sys.rayleigh_time_step();
  const Particles& p = sys.particles();
  for (long s = 0; s < 10'000'000; ++s) {
    sys.step(dt);
    const double gap =
        wall ? p.position[0].z() - r : (p.position[1] - p.position[0]).norm() - 2 * r;
    if (gap > 1e-4 * r && s > 10) break;  // apart again
  }
  return wall ? p.velocity[0].z() / v : (p.velocity[1].x() - p.velocity[0].x()) / v;
}

}  // namespace

TEST_CASE("dem: the default time step realises the restitution to 1 % for 0.1 <= e <= 1",
          "[dem][physics][slow]") {
  for (double e : {0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0}) {
    double worst = 0.0;
    for (double v : {0.01, 0.1, 1.0, 3.0, 10.0})
      for (bool wall : {false, true}) {
        const double ratio = realised(e, v, wall) / e;
        INFO("e " << e << ", v " << v << (wall ? " on a wall" : " two spheres") << ": realised "
                  << ratio * e);
        CHECK(std::abs(ratio - 1.0) < 0.01);
        worst = std::max(worst, std::abs(ratio - 1.0));
      }
    WARN("e " << e << ": fraction " << RestitutionCalibration::time_step_fraction(e)
              << ", worst relative error " << worst);
  }
  // what the old default did (documented in RestitutionCalibration::time_step_fraction)
  CHECK(realised(0.1, 1.0, false, 0.2) / 0.1 < 0.985);
}

TEST_CASE("dem: the system's time step fraction is the smallest over the interactions in use",
          "[dem]") {
  System sys;
  const int a = sys.add_material({1e9, 0.3, 2500.0});
  const int b = sys.add_material({1e9, 0.3, 2500.0});
  sys.add_interaction(a, a, {0.3, 0.9, 0.0});
  sys.add_interaction(a, b, {0.3, 0.1, 0.0});
  sys.add_interaction(b, b, {0.3, 0.1, 0.0});
  sys.add_particle({0, 0, 0}, 1e-3, a);
  CHECK(sys.time_step_fraction() == RestitutionCalibration::time_step_fraction(0.9));
  sys.add_plane({0, 0, -1}, {0, 0, 1}, b);  // a wall of b: the pair (a, b) is now in use
  CHECK(sys.time_step_fraction() == RestitutionCalibration::time_step_fraction(0.1));
}
