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

TEST_CASE("dem: the step profile adds up and changes no bit", "[dem][threads]") {
  // System::StepProfile: per thread, the phases of a fused step are consecutive clock readings
  // from the fork to the join, so they add up to the region's wall; the region lies within the
  // fused steps' wall, those within all steps'. Reading the clock changes nothing in the physics.
  const int before = max_threads();
  for (int threads : {1, 2, 3}) {
    set_num_threads(threads);
    System profiled = falling_bed();
    System plain = falling_bed();
    const double dt = 0.2 * profiled.rayleigh_time_step();
    profiled.set_step_profiling(true);
    profiled.run(300, dt);
    plain.run(300, dt);
    INFO(threads << " threads");
    const Particles& p = profiled.particles();
    const Particles& q = plain.particles();
    CHECK(p.position == q.position);
    CHECK(p.velocity == q.velocity);
    CHECK(p.angular_velocity == q.angular_velocity);
    CHECK(profiled.wall_force(0) == plain.wall_force(0));

    const System::StepProfile& prof = profiled.step_profile();
    CHECK(prof.steps == 300);
    // the bed is rebuilt now and then (at least 6 times: the fused-step test above), not at
    // every step, and the fused path is taken between rebuilds
    CHECK(prof.fused_steps > 0);
    CHECK(prof.fused_steps < prof.steps);
    CHECK(prof.step_s >= prof.fused_step_s);
    CHECK(prof.fused_step_s >= prof.fused_region_s);
    CHECK(prof.fused_region_s >= prof.fused_slowest_s);
    CHECK(prof.fused_slowest_s > 0.0);
    int team = 0;
    for (const System::StepProfile::Thread& t : prof.threads) {
      const double sum = t.enter + t.drift + t.drift_wait + t.cross + t.cross_wait + t.rows +
                         t.join_wait;
      if (sum == 0.0) continue;
      ++team;
      for (double v : {t.enter, t.drift, t.drift_wait, t.cross, t.cross_wait, t.rows, t.join_wait})
        CHECK(v >= 0.0);
      CHECK(t.rows > 0.0);
      CHECK(sum == Approx(prof.fused_region_s).epsilon(1e-9));
    }
    CHECK(team == threads);  // > 1024 particles: one part a thread

    // off: the profile stays as it was
    const long steps = prof.steps;
    const double wall = prof.step_s;
    profiled.set_step_profiling(false);
    profiled.run(10, dt);
    CHECK(profiled.step_profile().steps == steps);
    CHECK(profiled.step_profile().step_s == wall);
  }
  set_num_threads(before);
}
