// DEM inputs: absurd extents, a single particle's self-interaction, the faces of a box wall.
#include <catch2/catch.hpp>

#include "dem_test_helpers.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/system.hpp"

#include <cmath>
#include <string>

using namespace partita::dem;

namespace {

// A cubic lattice of k^3 spheres of radius r, spacing 2.2 r, from the origin.
void add_lattice(System& sys, int k, double r, int material) {
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l)
        sys.add_particle(Eigen::Vector3d(2.2 * r * i, 2.2 * r * j, 2.2 * r * l), r, material);
}

}  // namespace

TEST_CASE("dem: a particle far from the bed is an error naming it, not a huge grid",
          "[dem][robustness]") {
  // 21^3 = 9,261 spheres of 1 mm and one 880 m away (a unit slip): the grid of 2.2 mm cells
  // would need 4e5 cells along x (10^17 along three axes); capped at 4 N + 64 cells it would
  // put the bed in one cell and compare every pair. The step refuses, naming the particle.
  System sys = test::single_material(1.0e8, 0.3, 2500.0, 0.5, 0.3);
  add_lattice(sys, 21, 1.0e-3, 0);
  const std::size_t far = sys.add_particle(Eigen::Vector3d(880.0, 880.0, 880.0), 1.0e-3, 0);
  const std::int64_t far_id = sys.particles().id[far];
  sys.set_sort_interval(1);  // the cell order is computed first: it must not overflow either
  try {
    sys.step(0.1 * sys.rayleigh_time_step());
    FAIL("the step accepted a bed with one particle 880 m away");
  } catch (const Error& e) {
    const std::string m = e.what();
    INFO(m);
    CHECK(m.find("particle id " + std::to_string(far_id)) != std::string::npos);
    CHECK(m.find("(880, 880, 880)") != std::string::npos);
    CHECK(m.find("the particles span") != std::string::npos);
  }
}

TEST_CASE("dem: a few particles far apart step without a huge grid", "[dem][robustness]") {
  // Radius 10 um and 880 m apart along every axis: 4e7 natural cells per axis, 6e22 in all (the
  // product overflowed a 64-bit count before). A small cloud is searched in few wide cells.
  System sys = test::single_material(1.0e8, 0.3, 2500.0, 0.5, 0.3);
  sys.set_gravity(Eigen::Vector3d::Zero());
  sys.add_particle(Eigen::Vector3d::Zero(), 1.0e-5, 0, Eigen::Vector3d(1.0, 0, 0));
  sys.add_particle(Eigen::Vector3d(3.0e-5, 0, 0), 1.0e-5, 0);
  sys.add_particle(Eigen::Vector3d(880.0, 880.0, 880.0), 1.0e-5, 0);
  sys.set_sort_interval(1);
  const double dt = 0.1 * sys.rayleigh_time_step();
  REQUIRE_NOTHROW(sys.run(2000, dt));  // 5.4e-5 s: they meet after 1e-5 s
  // the two near particles met: the search found them in the wide cells; momentum is conserved
  // and e = 0.5 leaves the first with 1/4 and the second with 3/4 of the speed
  const Particles& p = sys.particles();
  double v0 = 0.0, v1 = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.id[i] == 0) v0 = p.velocity[i].x();
    if (p.id[i] == 1) v1 = p.velocity[i].x();
  }
  CHECK(v0 + v1 == Approx(1.0).epsilon(1e-9));
  CHECK(v1 == Approx(0.75).epsilon(0.02));
}

TEST_CASE("dem: one particle needs no interaction of its material with itself",
          "[dem][robustness]") {
  System sys;
  const int ball = sys.add_material({2.0e11, 0.3, 7800.0});
  const int floor = sys.add_material({5.0e10, 0.25, 2700.0});
  sys.add_interaction(ball, floor, {0.3, 0.5, 0.0});
  sys.add_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), floor);
  sys.add_particle(Eigen::Vector3d(0, 0, 0.01), 1.0e-3, ball);
  // the fraction comes from the one pair that can touch (e = 0.5: 0.1)
  CHECK(sys.time_step_fraction() == 0.1);
  REQUIRE_NOTHROW(sys.run(10, 0.1 * sys.rayleigh_time_step()));
  // a second ball can touch the first: now ball-ball is needed, and the message names it
  sys.add_particle(Eigen::Vector3d(0, 0, 0.02), 1.0e-3, ball);
  CHECK_THROWS_WITH(sys.step(0.1 * sys.rayleigh_time_step()),
                    Catch::Contains("no interaction between materials 0 and 0"));
  // particles of two materials that can touch each other still need their pair
  System two;
  const int a = two.add_material({1.0e9, 0.3, 2500.0});
  const int b = two.add_material({1.0e9, 0.3, 2500.0});
  two.add_particle(Eigen::Vector3d::Zero(), 1.0e-3, a);
  two.add_particle(Eigen::Vector3d(0.01, 0, 0), 1.0e-3, b);
  CHECK_THROWS_WITH(two.step(1.0e-7), Catch::Contains("no interaction between materials 0 and 1"));
}

TEST_CASE("dem: a box wall's faces carry their parts of its force", "[dem][robustness][walls]") {
  // A settled bed in a box open at the top: the floor (-z face) carries the weight, the side
  // faces only horizontal forces, and the faces add up to the wall's total.
  System sys = test::single_material(5.0e6, 0.3, 2500.0, 0.3, 0.4);
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(Eigen::Vector3d::Zero(),
                                            Eigen::Vector3d(6e-3, 6e-3, 6e-3), 1.0e-3, 0.8e-3,
                                            0.6, 5);
  sys.add_particles(pk.positions, pk.radii, 0);
  const int box = sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(6e-3, 6e-3, 12e-3), 0,
                              0b011111);  // open top
  const double dt = 0.1 * sys.rayleigh_time_step();
  sys.run(static_cast<int>(0.08 / dt), dt);  // 80 ms: settled
  double weight = 0.0;
  for (const double m : sys.particles().mass) weight += 9.81 * m;
  const auto floor = sys.wall_face_force(box, 4);
  REQUIRE(floor.has_value());
  CHECK_FALSE(sys.wall_face_force(box, 5).has_value());  // the open top
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int face = 0; face < 5; ++face) {
    const Eigen::Vector3d f = *sys.wall_face_force(box, face);
    // each face is pushed outwards along its axis: -x for xmin, +x for xmax, ...; the floor
    // down, the side faces only by friction along z
    const double sign = face % 2 == 0 ? -1.0 : 1.0;
    CHECK(sign * f[face / 2] > 0.0);
    if (face < 4) CHECK(std::abs(f.z()) < 0.2 * weight);
    sum += f;
  }
  // at rest the wall carries the weight, the floor most of it (friction on the side faces the
  // rest: Janssen), and the faces add up to the wall's force (the same additions, in plane order)
  CHECK(sum.z() == Approx(-weight).epsilon(0.01));
  CHECK(floor->z() < -0.8 * weight);
  CHECK((sum - sys.wall_force(box)).norm() <= 1e-12 * weight);
  CHECK_THROWS_AS(sys.wall_face_force(box, 6), Error);
  CHECK_THROWS_AS(sys.wall_face_force(box + 1, 0), Error);
}
