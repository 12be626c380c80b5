// Normal and oblique impacts against Hertz theory, restitution of the calibrated damping.

#include "dem_test_helpers.hpp"

#include "partita/dem/restitution_calibration.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace partita::dem;
using partita::dem::test::HertzImpact;

namespace {

constexpr double E = 1.0e9, NU = 0.3, RHO = 2500.0, R = 1.0e-3;
const double E_STAR_SAME = E / (2.0 * (1.0 - NU * NU));

struct ImpactResult {
  double contact_time = 0.0, delta_max = 0.0, force_max = 0.0;
  Eigen::Vector3d v_after = Eigen::Vector3d::Zero(), w_after = Eigen::Vector3d::Zero();
};

// Sphere of radius R starting just in touch with the floor z = 0, velocity v0 (v0.z < 0).
ImpactResult sphere_on_plane(double restitution, double friction, const Eigen::Vector3d& v0,
                             DampingModel damping = DampingModel::calibrated, double frac = 0.05) {
  System sys = test::single_material(E, NU, RHO, restitution, friction, damping);
  sys.add_particle({0.0, 0.0, R}, R, 0, v0);
  const int floor = sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  const double dt = frac * sys.rayleigh_time_step();
  ImpactResult res;
  double prev_delta = 0.0;
  for (int s = 0; s < 1'000'000; ++s) {
    sys.step(dt);
    const double delta = R - sys.particles().position[0].z();
    res.delta_max = std::max(res.delta_max, delta);
    res.force_max = std::max(res.force_max, -sys.wall_force(floor).z());
    if (delta < 0.0) {
      res.contact_time = sys.time() - dt + dt * prev_delta / (prev_delta - delta);
      break;
    }
    prev_delta = delta;
  }
  sys.run(5, dt);  // well clear of the plane
  res.v_after = sys.particles().velocity[0];
  res.w_after = sys.particles().angular_velocity[0];
  return res;
}

}  // namespace

TEST_CASE("dem: sphere-sphere normal impact matches Hertz theory", "[dem][physics]") {
  const double v = 1.0;  // relative speed
  System sys = test::single_material(E, NU, RHO, 1.0, 0.0);
  sys.add_particle({-R, 0, 0}, R, 0, {0.5 * v, 0, 0});
  sys.add_particle({R, 0, 0}, R, 0, {-0.5 * v, 0, 0});
  const double dt = 0.05 * sys.rayleigh_time_step();
  double delta_max = 0.0, force_max = 0.0, prev = 0.0, t_c = 0.0;
  for (int s = 0; s < 1'000'000; ++s) {
    sys.step(dt);
    const double delta =
        2.0 * R - (sys.particles().position[1] - sys.particles().position[0]).norm();
    delta_max = std::max(delta_max, delta);
    force_max = std::max(force_max, sys.particles().force[0].norm());
    if (delta < 0.0) {
      t_c = sys.time() - dt + dt * prev / (prev - delta);
      break;
    }
    prev = delta;
  }
  const double m = test::sphere_mass(R, RHO);
  const HertzImpact th(0.5 * m, 0.5 * R, E_STAR_SAME, v);
  INFO("delta_max " << delta_max << " theory " << th.delta_max << "; F_max " << force_max
                    << " theory " << th.force_max << "; t_c " << t_c << " theory "
                    << th.contact_time);
  CHECK(delta_max == Approx(th.delta_max).epsilon(0.02));
  CHECK(force_max == Approx(th.force_max).epsilon(0.02));
  CHECK(t_c == Approx(th.contact_time).epsilon(0.02));
  // elastic and frictionless: the spheres leave with their initial speeds
  CHECK(sys.particles().velocity[0].x() == Approx(-0.5 * v).epsilon(1e-4));
}

TEST_CASE("dem: sphere-plane normal impact matches Hertz theory", "[dem][physics]") {
  const double v = 1.0;
  const ImpactResult r = sphere_on_plane(1.0, 0.0, {0, 0, -v});
  const HertzImpact th(test::sphere_mass(R, RHO), R, E_STAR_SAME, v);
  INFO("delta_max " << r.delta_max << " theory " << th.delta_max << "; F_max " << r.force_max
                    << " theory " << th.force_max << "; t_c " << r.contact_time << " theory "
                    << th.contact_time);
  CHECK(r.delta_max == Approx(th.delta_max).epsilon(0.02));
  CHECK(r.force_max == Approx(th.force_max).epsilon(0.02));
  CHECK(r.contact_time == Approx(th.contact_time).epsilon(0.02));
  CHECK(r.v_after.z() == Approx(v).epsilon(1e-4));
}

TEST_CASE("dem: calibrated damping realises the requested restitution at any speed",
          "[dem][physics]") {
  for (double e : {0.1, 0.5, 0.9}) {
    double lo = 1e9, hi = -1e9;
    for (double v : {0.1, 0.3, 1.0}) {
      const ImpactResult r = sphere_on_plane(e, 0.0, {0, 0, -v});
      const double ratio = r.v_after.z() / v;
      INFO("e " << e << " v " << v << " rebound ratio " << ratio);
      CHECK(ratio == Approx(e).epsilon(0.02));
      lo = std::min(lo, ratio);
      hi = std::max(hi, ratio);
    }
    INFO("e " << e << " spread of the rebound ratio over v = 0.1..1 m/s: " << (hi - lo) / e);
    CHECK((hi - lo) / e < 0.01);
  }
}

TEST_CASE("dem: LIGGGHTS damping realises the restitution of its damping ratio", "[dem][physics]") {
  // The simulation must agree with the scaled-oscillator prediction for its zeta (no tension
  // clamp). Measured: without the clamp the LIGGGHTS zeta(e) realises e to ~1e-5 in the scaled
  // equation; with the clamp (no attraction) it does not, hence the calibrated default.
  for (double e : {0.1, 0.5, 0.9}) {
    const double predicted = RestitutionCalibration::restitution(
        RestitutionCalibration::liggghts_damping_ratio(e), false);
    const double clamped = RestitutionCalibration::restitution(
        RestitutionCalibration::liggghts_damping_ratio(e), true);
    const ImpactResult r = sphere_on_plane(e, 0.0, {0, 0, -0.5}, DampingModel::liggghts, 0.01);
    INFO("LIGGGHTS-style e = " << e << " realises " << r.v_after.z() / 0.5 << ", predicted "
                               << predicted << ", with a no-tension clamp it would be " << clamped);
    CHECK(r.v_after.z() / 0.5 == Approx(predicted).epsilon(0.01));
    if (e < 0.9) CHECK(std::abs(clamped - e) > 0.01 * e);
  }
}

TEST_CASE("dem: oblique impact in gross sliding", "[dem][physics]") {
  const double mu = 0.3, e = 0.5, vn = 0.2, vt = 1.0;
  const ImpactResult r = sphere_on_plane(e, mu, {vt, 0, -vn});
  const double vt_expected = vt - mu * (1.0 + e) * vn;
  const double w_expected = 2.5 * mu * (1.0 + e) * vn / R;
  INFO("v_t' " << r.v_after.x() << " expected " << vt_expected << "; omega' " << r.w_after.y()
               << " expected " << w_expected << "; v_n' " << r.v_after.z());
  CHECK(r.v_after.z() == Approx(e * vn).epsilon(0.02));
  CHECK(r.v_after.x() == Approx(vt_expected).epsilon(0.02));
  CHECK(std::abs(r.w_after.y()) == Approx(w_expected).epsilon(0.02));
  CHECK(r.w_after.y() > 0.0);  // rolls forward in +x: spin about +y
}

TEST_CASE("dem: rolling resistance decelerates a rolling sphere at 5/7 mu_r g", "[dem][physics]") {
  // Constant rolling torque mu_r F_n R on a sphere rolling without slip on a plane:
  // (m + I/R^2) dv/dt = -mu_r m g  =>  dv/dt = -5/7 mu_r g.
  const double mu_r = 0.05, g = 9.81, v0 = 0.2;
  System sys;
  const int m = sys.add_material({E, NU, RHO});
  sys.add_interaction(m, m, {0.5, 0.5, mu_r});
  sys.set_gravity({0, 0, -g});
  const double delta0 =
      std::pow(3.0 * test::sphere_mass(R, RHO) * g / (4.0 * E_STAR_SAME * std::sqrt(R)), 2.0 / 3.0);
  sys.add_particle({0, 0, R - delta0}, R, m, {v0, 0, 0}, {0, v0 / R, 0});
  sys.add_plane({0, 0, 0}, {0, 0, 1}, m);
  const double dt = 0.2 * sys.rayleigh_time_step();
  const double t_end = 0.5 * v0 / (5.0 / 7.0 * mu_r * g);  // half way to rest
  sys.run(static_cast<long>(t_end / dt), dt);
  const double expected = v0 - 5.0 / 7.0 * mu_r * g * sys.time();
  INFO("v " << sys.particles().velocity[0].x() << " expected " << expected);
  CHECK(sys.particles().velocity[0].x() == Approx(expected).epsilon(0.02));
}
