// The step with the integrator's first half inside the force pass (taken when the last step's
// motion bound shows that no neighbour-list rebuild can be due) gives the same bits as the step
// with a first-half loop of its own and the exact rebuild decision. A restored state has no
// motion bound, so a run that saves and restores its state before every step takes the exact
// path throughout; an uninterrupted run takes the fused one wherever the bound allows.

#include "dem_test_helpers.hpp"

#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

using namespace partita::dem;

namespace {

// Stirred granules falling into a box: fast enough that the lists are rebuilt many times (every
// path of the step: fused, exact, exact with a rebuild). (No mesh: a state saved while no particle
// is near a mesh does not read back, "the mesh contact rows do not agree", in main as here.)
System falling_bed() {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.05});
  sys.set_gravity({0, 0, -9.81});
  const double box = 14e-3;
  const Packing pk = test::two_size_packing(Eigen::Vector3d(0, 0, 1e-3),
                                            Eigen::Vector3d(box, box, box), 1.2e-3, 0.8e-3, 0.6, 9);
  sys.add_particles(pk.positions, pk.radii, m);
  for (std::size_t i = 0; i < sys.particle_count(); ++i)  // stirred: up to 0.4 m/s, some spin
    sys.set_particle_velocity(i, Eigen::Vector3d(i % 3 - 1.0, i % 5 - 2.0, i % 7 - 3.0) * 0.1,
                              Eigen::Vector3d(0, 0, i % 2 ? 100.0 : -100.0));
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2 * box), m, 0b001111);
  return sys;
}

}  // namespace

TEST_CASE("dem: the fused step gives the bits of the step with the exact rebuild decision",
          "[dem][state][threads]") {
  const int before = max_threads();
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    System fused = falling_bed();
    System exact = falling_bed();
    const double dt = 0.2 * fused.rayleigh_time_step();
    for (int k = 0; k < 300; ++k) {
      fused.step(dt);
      exact.restore_state(exact.save_state());  // forgets the motion bound
      exact.step(dt);
    }
    INFO(threads << " threads, " << fused.particle_count() << " particles");
    CHECK(fused.particle_count() > 1024);  // parts run in parallel with 2 threads
    CHECK(fused.neighbor_list().build_count() > 5);
    CHECK(fused.neighbor_list().build_count() == exact.neighbor_list().build_count());
    const Particles& p = fused.particles();
    const Particles& q = exact.particles();
    CHECK(p.position == q.position);
    CHECK(p.velocity == q.velocity);
    CHECK(p.angular_velocity == q.angular_velocity);
    CHECK(p.force == q.force);
    CHECK(p.torque == q.torque);
    CHECK(fused.wall_force(0) == exact.wall_force(0));
  }
  set_num_threads(before);
}
