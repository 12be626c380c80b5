// Energy conservation of a dense random packing and the static load of a settled column.

#include "dem_test_helpers.hpp"

#include "partita/dem/packing_generator.hpp"

#include <catch2/catch.hpp>

#include <cstdint>

using namespace partita::dem;

namespace {

// Deterministic velocities in [-a, a]^3 (SplitMix64).
Eigen::Vector3d random_velocity(std::uint64_t& s, double a) {
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    v[k] = a * (2.0 * static_cast<double>(z >> 11) * 0x1.0p-53 - 1.0);
  }
  return v;
}

// A column of about 100 spheres (radii 0.5 and 0.6 mm) generated in [0, 4 mm]^2 x [z0, z0 + 12 mm]
// over a floor at z = 0 (id floor), between four frictionless side walls (id sides: they carry no
// vertical load), friction 0.5 between spheres and with the floor, restitution 0.3, gravity.
struct Column {
  System sys;
  int floor = -1, sides = -1;
  double weight = 0.0;  // sum m g [N]
  explicit Column(double z0) {
    const int grain = sys.add_material({1.0e7, 0.3, 2500.0});
    const int smooth = sys.add_material({1.0e7, 0.3, 2500.0});
    sys.add_interaction(grain, grain, {0.5, 0.3, 0.0});
    sys.add_interaction(grain, smooth, {0.0, 0.3, 0.0});
    sys.set_gravity({0, 0, -9.81});
    const Packing pk = test::two_size_packing(Eigen::Vector3d(0, 0, z0),
                                              Eigen::Vector3d(4e-3, 4e-3, z0 + 12e-3), 1.2e-3,
                                              1.0e-3, 0.6, 11);
    sys.add_particles(pk.positions, pk.radii, grain);
    floor = sys.add_plane({0, 0, 0}, {0, 0, 1}, grain);
    sides = sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(4e-3, 4e-3, 1.0), smooth,
                        0b001111);  // four sides
    for (double m : sys.particles().mass) weight += 9.81 * m;
  }
};

}  // namespace

TEST_CASE("dem: energy is conserved without damping or friction", "[dem][physics]") {
  // ~150 spheres at 45 % solids in a closed box, random velocities, e = 1, mu = 0, no gravity:
  // E = kinetic + sum over contacts 8/15 E* sqrt(R*) delta^(5/2) (spheres and walls).
  const Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi(8e-3, 8e-3, 8e-3);
  const Packing pk = test::two_size_packing(lo, hi, 1.6e-3, 1.2e-3, 0.55, 7);
  System sys = test::single_material(1.0e7, 0.3, 2500.0, 1.0, 0.0);
  sys.add_particles(pk.positions, pk.radii, 0);
  sys.add_box(lo, hi, 0);
  std::uint64_t seed = 3;
  for (std::size_t i = 0; i < sys.particle_count(); ++i)
    sys.set_particle_velocity(i, random_velocity(seed, 0.2));
  const double dt = 0.1 * sys.rayleigh_time_step();
  const double e0 = sys.kinetic_energy() + sys.elastic_energy();
  double max_drift = 0.0;
  long contacts = 0;
  for (int block = 0; block < 100; ++block) {
    sys.run(1000, dt);
    const double e = sys.kinetic_energy() + sys.elastic_energy();
    max_drift = std::max(max_drift, std::abs(e - e0) / e0);
    contacts += static_cast<long>(sys.contact_count());
  }
  INFO(sys.particle_count() << " particles, 1e5 steps, " << contacts / 100.0
                            << " contacts on average, max relative energy drift " << max_drift);
  CHECK(sys.step_count() == 100000);
  CHECK(contacts > 0);
  CHECK(max_drift < 1e-3);
}

TEST_CASE("dem: a settled column puts its whole weight on the floor", "[dem][physics]") {
  // Frictionless side walls (they carry no vertical load), friction between spheres and with
  // the floor, restitution 0.3: at rest the floor force equals the total weight.
  Column c(0.0);
  System& sys = c.sys;
  const int floor = c.floor;
  const double weight = c.weight;
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(static_cast<long>(0.2 / dt), dt);  // 0.2 s
  double mean = 0.0;
  const int n_avg = 2000;
  for (int s = 0; s < n_avg; ++s) {
    sys.step(dt);
    mean += -sys.wall_force(floor).z() / n_avg;
  }
  INFO(sys.particle_count() << " spheres, weight " << weight << " N, floor force " << mean
                            << " N, kinetic energy " << sys.kinetic_energy() << " J");
  CHECK(mean == Approx(weight).epsilon(0.005));
}

TEST_CASE("dem: impulse balance of a falling column: walls' impulse = weight's + momentum's change",
          "[dem][physics]") {
  // Newton's second law for the whole bed (the pair forces cancel): d/dt sum m v = M g + the
  // walls' forces on the particles. While the column falls and hits the floor, the
  // floor force is far from the weight at any moment, but over any interval
  // integral(-W_z) dt - M g t = P_z(t) - P_z(0) (W: the particles' force on the walls, the
  // integral by the trapezoidal rule over the steps, as the velocity update takes it).
  Column c(2e-3);  // 2 mm above the floor
  System& sys = c.sys;
  const int floor = c.floor, sides = c.sides;
  const double weight = c.weight;
  const double dt = 0.2 * sys.rayleigh_time_step();
  auto wall_force_on_bed = [&] { return -(sys.wall_force(floor).z() + sys.wall_force(sides).z()); };
  sys.step(dt);
  const double p0 = sys.linear_momentum().z();
  double f0 = wall_force_on_bed(), impulse = 0.0, floor_mean = 0.0;
  const long steps = static_cast<long>(0.024 / dt);  // 24 ms: the fall of 2 mm (20 ms), the impact
  for (long s = 0; s < steps; ++s) {
    sys.step(dt);
    const double f1 = wall_force_on_bed();
    impulse += 0.5 * dt * (f0 + f1);
    floor_mean += -sys.wall_force(floor).z() / static_cast<double>(steps);
    f0 = f1;
  }
  const double t = static_cast<double>(steps) * dt;
  const double dp = sys.linear_momentum().z() - p0;
  INFO(sys.particle_count() << " spheres, " << steps << " steps: weight " << weight
                            << " N, mean floor force " << floor_mean << " N, momentum change "
                            << dp << " kg m/s, walls' impulse - weight's " << impulse - weight * t);
  // not at rest: the mean floor force over the interval is not the weight
  CHECK(std::abs(floor_mean / weight - 1.0) > 0.05);
  // the impulse balance closes to a small fraction of the weight's impulse
  CHECK(dp == Approx(impulse - weight * t).margin(1e-3 * weight * t));
}

TEST_CASE("dem: wide size distribution: a large sphere rests on a bed of small ones",
          "[dem][physics]") {
  // Radius ratio 10: cells are sized by the largest sphere; every contact must still be found.
  // A 5 mm sphere settles on a layer of 0.5 mm spheres: the floor carries the total weight and
  // the large sphere does not fall through.
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.3, 0.3, 0.0});
  sys.set_gravity({0, 0, -9.81});
  const double r = 0.5e-3, big = 5e-3, w = 12e-3;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) sys.add_particle({r + 2 * r * i, r + 2 * r * j, r}, r, m);
  const std::size_t b = sys.add_particle({w / 2, w / 2, 2 * r + big + 1e-4}, big, m);
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(w, w, 1.0), m, 0b011111);
  double weight = 0.0;
  for (double mass : sys.particles().mass) weight += 9.81 * mass;
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(static_cast<long>(0.3 / dt), dt);
  double mean = 0.0;
  for (int s = 0; s < 2000; ++s) {
    sys.step(dt);
    mean += -sys.wall_force(0).z() / 2000;
  }
  INFO("floor force " << mean << " N, weight " << weight
                      << " N, big sphere at z = " << sys.particles().position[b].z());
  CHECK(sys.particles().position[b].z() > r + big);  // held by the small spheres, not the floor
  CHECK(mean == Approx(weight).epsilon(0.005));
}
