// The step loop allocates no memory once its arrays have their size: not in a plain step, not in
// a step that rebuilds the neighbour lists, with one thread or two; nor a split bed's step between
// its list builds. The global operator new of
// the test program is replaced by one that counts (forwarding to malloc).

#include "dem_test_helpers.hpp"

#include "partita/dem/breakage.hpp"
#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/subdomain.hpp"
#include "partita/dem/system.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define PARTITA_COUNT_ALLOCATIONS 0  // keep the sanitizer's own operator new
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PARTITA_COUNT_ALLOCATIONS 0
#else
#define PARTITA_COUNT_ALLOCATIONS 1
#endif
#else
#define PARTITA_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<long> allocations{0};
}

#if PARTITA_COUNT_ALLOCATIONS
void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
#endif

using namespace partita::dem;

namespace {

// A packed bed drifting at constant velocity without gravity: lists are rebuilt every few steps
// while the neighbourhoods stay the same, so every rebuild reuses the arrays of the first.
System drifting_bed(bool counter_moving = false) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.05});
  const Packing pk = test::two_size_packing(
      Eigen::Vector3d::Zero(), Eigen::Vector3d(12e-3, 12e-3, 12e-3), 1.2e-3, 0.8e-3, 0.6, 3);
  sys.add_particles(pk.positions, pk.radii, m);
  for (std::size_t i = 0; i < sys.particle_count(); ++i)
    sys.set_particle_velocity(
        i, (counter_moving && i % 2 ? -1.0 : 1.0) * Eigen::Vector3d(0.5, 0.2, 0.0));
  sys.add_plane({0, 0, -1.0}, {0, 0, 1}, m);  // far away: checked, never touched
  return sys;
}

}  // namespace

TEST_CASE("dem: steps allocate no memory with or without a list rebuild", "[dem][performance]") {
  if (!PARTITA_COUNT_ALLOCATIONS) SUCCEED("allocation counting is off in sanitizer builds");
  const int before = max_threads();
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    System sys = drifting_bed();
    REQUIRE(sys.particle_count() > 1024);  // the parallel path
    const double dt = 0.2 * sys.rayleigh_time_step();
    sys.run(100, dt);  // first steps size the arrays
    const long builds = sys.neighbor_list().build_count();
    if (PARTITA_COUNT_ALLOCATIONS) CHECK(allocations.load() > 0);  // the counter does count
    const long count = allocations.load();
    sys.run(400, dt);
    const long made = allocations.load() - count;
    const long rebuilt = sys.neighbor_list().build_count() - builds;
    INFO(threads << " threads: " << made << " allocations in 400 steps with " << rebuilt
                 << " list rebuilds");
    CHECK(rebuilt >= 2);  // the rebuild path was taken
    if (PARTITA_COUNT_ALLOCATIONS) CHECK(made == 0);
  }
  set_num_threads(before);
}

TEST_CASE("dem: renumbering the particles at list builds allocates no memory either",
          "[dem][performance]") {
  // half the particles moving against the other half: cells change, every build renumbers
  System sys = drifting_bed(true);
  sys.set_sort_interval(1);
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(200, dt);
  const long sorts = sys.sort_count();
  const long count = allocations.load();
  sys.run(400, dt);
  const long made = allocations.load() - count;
  INFO(made << " allocations in 400 steps with " << sys.sort_count() - sorts << " renumberings");
  CHECK(sys.sort_count() - sorts >= 2);
  if (PARTITA_COUNT_ALLOCATIONS) CHECK(made == 0);
}

TEST_CASE("dem: steps with a mesh under the bed allocate no memory (renumbering included)",
          "[dem][performance][mesh]") {
  // the bed drifts sideways over a large flat mesh: the particles near it stay much the same, so
  // the mesh contact rows keep about their size (the first steps size them); sort interval 1:
  // half the bed moves against the other half, every build renumbers (rows follow)
  for (const int sort : {0, 1}) {
    System sys = drifting_bed(sort > 0);
    sys.set_sort_interval(sort);
    Eigen::MatrixX3d v(4, 3);
    v << -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0;
    TriangleMesh::Triangles t(2, 3);
    t << 0, 1, 2, 0, 2, 3;
    sys.add_mesh(v, t, 0);
    const double dt = 0.2 * sys.rayleigh_time_step();
    sys.run(100, dt);
    const std::size_t rows = sys.mesh_contacts().row_count();
    const long builds = sys.neighbor_list().build_count();
    const long sorts = sys.sort_count();
    const long count = allocations.load();
    sys.run(400, dt);
    const long made = allocations.load() - count;
    INFO(made << " allocations in 400 steps with " << sys.neighbor_list().build_count() - builds
              << " list rebuilds, " << sys.sort_count() - sorts << " renumberings, sort interval "
              << sort << ", " << rows << " -> " << sys.mesh_contacts().row_count() << " mesh rows");
    CHECK(rows > 0);                         // the bottom layer is within R + skin of the mesh
    CHECK(rows < sys.particle_count() / 4);  // and only it
    CHECK(sys.neighbor_list().build_count() - builds >= 2);
    if (sort > 0) CHECK(sys.sort_count() - sorts >= 2);
    if (PARTITA_COUNT_ALLOCATIONS) CHECK(made == 0);
  }
}

TEST_CASE("dem: steps with breakage enabled but nothing breaking allocate no memory",
          "[dem][performance][breakage]") {
  const int before = max_threads();
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    System sys = drifting_bed(true);
    BreakageParameters b;
    b.limit_strength = 1e12;  // far above any contact pressure here
    b.reference_size = 1e-3;
    b.weibull_modulus = 3.0;
    b.comminution_limit = 1e-4;
    const int hook = sys.add_hook(std::make_unique<Breakage>(b));
    const double dt = 0.2 * sys.rayleigh_time_step();
    sys.run(100, dt);  // first steps size the arrays and draw the strengths
    const long builds = sys.neighbor_list().build_count();
    const long count = allocations.load();
    sys.run(400, dt);
    const long made = allocations.load() - count;
    const long rebuilt = sys.neighbor_list().build_count() - builds;
    INFO(threads << " threads: " << made << " allocations in 400 steps with " << rebuilt
                 << " list rebuilds");
    CHECK(rebuilt >= 2);
    CHECK(static_cast<const Breakage&>(sys.hook(hook)).counters().events == 0);
    CHECK(sys.contact_count() > 0);  // loads were recorded, just below the strengths
    if (PARTITA_COUNT_ALLOCATIONS) CHECK(made == 0);
  }
  set_num_threads(before);
}

TEST_CASE("dem: a split bed's steps between list builds allocate no memory",
          "[dem][performance][subdomains]") {
  // the drifting bed cut in two across its motion: particles cross the cut at the builds; the
  // steps between them refresh the ghosts through buffers that keep their size
  System a = drifting_bed(), b = drifting_bed();
  std::vector<Eigen::Vector3d> x(a.particles().position.begin(), a.particles().position.end());
  const DomainDecomposition d = DomainDecomposition::bisection(
      x, Eigen::Vector3d::Zero(), Eigen::Vector3d(12e-3, 12e-3, 12e-3), 2);
  std::vector<char> not_a(x.size()), not_b(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    not_a[i] = d.owner(x[i]) != 0;
    not_b[i] = d.owner(x[i]) != 1;
  }
  a.remove_particles(not_a);
  b.remove_particles(not_b);
  InProcessTransport transport(2);
  SubdomainStepper stepper({&a, &b}, transport, d, 0.06e-3);
  const double dt = 0.2 * a.rayleigh_time_step();
  stepper.run(100, dt);  // first steps size the arrays and buffers
  long made = 0, quiet_steps = 0;
  const long builds = stepper.builds();
  for (int s = 0; s < 300; ++s) {
    const long before = stepper.builds(), count = allocations.load();
    stepper.step(dt);
    if (stepper.builds() != before) continue;
    made += allocations.load() - count;
    ++quiet_steps;
  }
  INFO(made << " allocations in " << quiet_steps << " steps between builds, "
            << stepper.builds() - builds << " builds");
  CHECK(stepper.builds() - builds >= 2);
  CHECK(quiet_steps > 100);
  CHECK(stepper.subdomain(0).migrated_in() + stepper.subdomain(1).migrated_in() > 0);
  CHECK(stepper.subdomain(0).ghost_count() > 0);
  if (PARTITA_COUNT_ALLOCATIONS) CHECK(made == 0);
}
