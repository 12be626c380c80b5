// The servo-controlled lid: it comes down onto a bed and presses it with the target force; the
// box then carries the target plus the bed's weight (equilibrium of the bed); bad parameters are
// refused; a state saved midway continues bit for bit.

#include <catch2/catch.hpp>

#include "dem_test_helpers.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/system.hpp"
#include "partita/dem/wall_servo.hpp"

#include <cmath>
#include <memory>
#include <numbers>

using namespace partita::dem;

namespace {

struct ServoBed {
  System sys;
  int box = -1, lid = -1;
  double weight = 0.0;
};

ServoBed servo_bed(double target) {
  ServoBed b;
  const double side = 6e-3;
  const int m = b.sys.add_material({1.0e7, 0.3, 2500.0});
  b.sys.add_interaction(m, m, {0.3, 0.5, 0.0});
  b.sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(Eigen::Vector3d::Zero(),
                                            Eigen::Vector3d(side, side, side), 1.2e-3, 0.8e-3,
                                            0.6, 3);
  b.sys.add_particles(pk.positions, pk.radii, m);
  for (Eigen::Index i = 0; i < pk.radii.size(); ++i)
    b.weight += 2500.0 * 4.0 / 3.0 * std::numbers::pi * std::pow(pk.radii[i], 3) * 9.81;
  b.box = b.sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(side, side, 3 * side), m,
                        0b011111);  // open at zmax
  const Eigen::Vector3d n(0, 0, -1);
  b.lid = b.sys.add_plane(Eigen::Vector3d(0, 0, side + 1e-3), n, m);
  WallServoParameters p;
  p.wall = b.lid;
  p.normal = n;
  p.force = target;
  p.max_velocity = 0.05;
  p.gain = p.max_velocity / target;
  b.sys.add_hook(std::make_unique<WallServo>(p));
  return b;
}

}  // namespace

TEST_CASE("wall servo: the lid presses the bed with the target force", "[dem][servo]") {
  const double target = 0.02;  // N, about ten times the bed's weight
  ServoBed b = servo_bed(target);
  const double dt = 0.2 * b.sys.rayleigh_time_step();
  b.sys.run(static_cast<int>(0.15 / dt), dt);  // 1 mm at 0.05 m/s (20 ms), then the approach
  // averages over 4 ms more: the lid's and the box's vertical forces
  const int n = static_cast<int>(4e-3 / dt);
  double lid = 0.0, box = 0.0;
  for (int k = 0; k < n; ++k) {
    b.sys.step(dt);
    lid += -b.sys.wall_force(b.lid).dot(Eigen::Vector3d(0, 0, -1)) / n;
    box += -b.sys.wall_force(b.box).z() / n;
  }
  INFO("lid " << lid << " N (target " << target << "), box " << box << " N, weight " << b.weight
              << " N");
  REQUIRE(b.weight > 0.0);
  // the controller's rest point
  CHECK(lid == Approx(target).epsilon(0.02));
  // the bed in equilibrium: what the lid and gravity push down, floor and side walls carry
  CHECK(box == Approx(target + b.weight).epsilon(0.02));
}

TEST_CASE("wall servo: a state saved midway continues bit for bit", "[dem][servo][state]") {
  ServoBed a = servo_bed(0.02);
  const double dt = 0.2 * a.sys.rayleigh_time_step();
  a.sys.run(3000, dt);  // the lid on its way down, touching the bed
  const SystemState saved = a.sys.save_state();
  a.sys.run(500, dt);
  const Eigen::Vector3d f_lid = a.sys.wall_force(a.lid);
  a.sys.restore_state(saved);
  a.sys.run(500, dt);
  CHECK(a.sys.wall_force(a.lid) == f_lid);
}

TEST_CASE("wall servo: bad parameters are refused", "[dem][servo][errors]") {
  WallServoParameters p;
  p.wall = 0;
  p.force = 1.0;
  p.max_velocity = 0.1;
  p.gain = 0.1;
  WallServoParameters q = p;
  q.force = -1.0;
  CHECK_THROWS_WITH(WallServo(q), Catch::Contains("target force must be > 0"));
  q = p;
  q.max_velocity = 0.0;
  CHECK_THROWS_WITH(WallServo(q), Catch::Contains("largest velocity"));
  q = p;
  q.gain = -2.0;
  CHECK_THROWS_WITH(WallServo(q), Catch::Contains("gain"));
  q = p;
  q.normal = Eigen::Vector3d::Zero();
  CHECK_THROWS_WITH(WallServo(q), Catch::Contains("normal"));
  System sys;
  q = p;
  q.wall = 3;
  CHECK_THROWS_AS(sys.add_hook(std::make_unique<WallServo>(q)), Error);
}
