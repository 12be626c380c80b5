// The monitors over every particle (kinetic energy, potential energy, momentum, contact count) and the state
// check (first_particle_astray) on beds large enough for their parallel passes: independent sums,
// the same bits on any number of threads, and the same values read from the packed state while
// stepping as from the store after a sync.

#include "dem_test_helpers.hpp"

#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

using namespace partita::dem;

namespace {

// A lattice of n x n x n spheres of radius r at spacing 2.5 r (no contacts) with velocities and
// spins that differ from particle to particle; no gravity (the energies are exact sums).
System lattice(int n, double r) {
  System sys = test::single_material(1.0e7, 0.3, 2500.0, 0.5, 0.3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const std::size_t id = sys.add_particle(Eigen::Vector3d(i, j, k) * 2.5 * r, r, 0);
        const double s = 1e-3 * static_cast<double>(id % 97);
        sys.set_particle_velocity(id, Eigen::Vector3d(s, -2.0 * s, 0.5 * s),
                                  Eigen::Vector3d(0.0, 10.0 * s, -s));
      }
  return sys;
}

}  // namespace

TEST_CASE("dem: monitors over a large bed: exact sums, any thread count, packed or synced",
          "[dem][threads]") {
  const int before = max_threads();
  const int n = 28;  // 21,952 particles: more than parallel_pass_min, so the passes run in parallel
  const double r = 1e-3;
  REQUIRE(n * n * n > parallel_pass_min);
  double ke[3] = {}, pe[3] = {}, pz[3] = {};
  std::size_t contacts[3] = {};
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    System sys = lattice(n, r);
    sys.set_gravity({0.0, 0.0, -9.81});
    const double dt = 0.1 * sys.rayleigh_time_step();
    sys.run(3, dt);  // the packed state is ahead of the store's copies
    const double ke_packed = sys.kinetic_energy();
    const double pe_packed = sys.potential_energy();
    const double pz_packed = sys.linear_momentum().z();

    // independently: long double sums over the synced store
    const Particles& p = sys.particles();
    long double ke_ref = 0.0L, pe_ref = 0.0L, pz_ref = 0.0L;
    for (std::size_t i = 0; i < p.size(); ++i) {
      pz_ref += static_cast<long double>(p.mass[i]) * p.velocity[i].z();
      ke_ref += 0.5L * p.mass[i] * p.velocity[i].squaredNorm() +
                0.5L * p.inertia[i] * p.angular_velocity[i].squaredNorm();
      pe_ref -= static_cast<long double>(p.mass[i]) * (-9.81 * p.position[i].z());
    }
    INFO(threads << " threads");
    CHECK(ke_packed == Approx(static_cast<double>(ke_ref)).epsilon(1e-12));
    CHECK(pe_packed == Approx(static_cast<double>(pe_ref)).epsilon(1e-12));
    CHECK(pz_packed == Approx(static_cast<double>(pz_ref)).epsilon(1e-12));
    CHECK(sys.linear_momentum().z() == pz_packed);
    CHECK(sys.kinetic_energy() == ke_packed);  // read from the store now: the same bits
    CHECK(sys.potential_energy() == pe_packed);
    ke[threads - 1] = ke_packed;
    pe[threads - 1] = pe_packed;
    pz[threads - 1] = pz_packed;
    contacts[threads - 1] = sys.contact_count();
  }
  set_num_threads(before);
  CHECK(ke[0] == ke[1]);
  CHECK(ke[0] == ke[2]);
  CHECK(pe[0] == pe[1]);
  CHECK(pe[0] == pe[2]);
  CHECK(pz[0] == pz[1]);
  CHECK(pz[0] == pz[2]);
  CHECK(contacts[0] == 0);  // spacing 2.5 r: no sphere touches another
  CHECK(contacts[1] == 0);
  CHECK(contacts[2] == 0);
}

TEST_CASE("dem: contact_count on a large touching bed is the same on any thread count",
          "[dem][threads]") {
  // a cubic lattice at spacing 1.9 r: every sphere touches its six neighbours (fewer on the
  // faces), 3 n^2 (n - 1) touching pairs in all
  const int before = max_threads();
  const int n = 26;  // 17,576 particles
  const double r = 1e-3;
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    System sys = test::single_material(1.0e7, 0.3, 2500.0, 0.5, 0.3);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) sys.add_particle(Eigen::Vector3d(i, j, k) * 1.9 * r, r, 0);
    REQUIRE(sys.particle_count() > static_cast<std::size_t>(parallel_pass_min));
    sys.step(0.01 * sys.rayleigh_time_step());  // builds the lists
    INFO(threads << " threads");
    CHECK(sys.contact_count() == static_cast<std::size_t>(3 * n * n * (n - 1)));
  }
  set_num_threads(before);
}

TEST_CASE("dem: first_particle_astray finds the lowest index outside the box", "[dem][threads]") {
  const int before = max_threads();
  const int n = 28;
  const double r = 1e-3;
  const double side = (n - 1) * 2.5 * r;
  const Eigen::Vector3d lo = Eigen::Vector3d::Constant(-r), hi = Eigen::Vector3d::Constant(side + r);
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    System sys = lattice(n, r);
    const double dt = 0.1 * sys.rayleigh_time_step();
    sys.run(2, dt);  // (packed state ahead; moves by at most 0.3 m/s x 2 dt: far below r)
    INFO(threads << " threads");
    CHECK(sys.first_particle_astray(lo, hi, 0.0) == -1);
    // a box that leaves out the top layer (z = side): its first particle is (0, 0, n - 1)
    const Eigen::Vector3d low_hi(side + r, side + r, side - r);
    CHECK(sys.first_particle_astray(lo, low_hi, 0.0) == n - 1);
    // ... unless the margin covers the layer
    CHECK(sys.first_particle_astray(lo, low_hi, 3.0 * r) == -1);
    // a box that leaves out the plane x = 0: particle 0
    const Eigen::Vector3d x_lo(r, -r, -r);
    CHECK(sys.first_particle_astray(x_lo, hi, 0.0) == 0);
    // the same from the synced store
    sys.particles();
    CHECK(sys.first_particle_astray(lo, low_hi, 0.0) == n - 1);
  }
  set_num_threads(before);
}
