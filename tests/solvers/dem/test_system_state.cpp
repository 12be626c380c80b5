// Save/restore, thread-count independence, errors, the peer bed reader and VTK output.

#include "dem_test_helpers.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/lammps_data.hpp"
#include "partita/dem/packing_generator.hpp"
#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

#include <array>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace partita::dem;

namespace {

// A granular bed falling under gravity into a box with a triangulated bump: every kind of
// contact and history is exercised (pairs, planes, mesh faces/edges/vertices, friction).
System falling_bed(double box, double porosity, std::uint64_t seed, bool backwards = false) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.05});
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(
      Eigen::Vector3d(0, 0, 1e-3), Eigen::Vector3d(box, box, box), 1.2e-3, 0.8e-3, porosity, seed);
  if (backwards)
    for (Eigen::Index k = pk.radii.size() - 1; k >= 0; --k)
      sys.add_particle(pk.positions.row(k).transpose(), pk.radii[k], m);
  else
    sys.add_particles(pk.positions, pk.radii, m);
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2 * box), m, 0b001111);
  Eigen::MatrixX3d v(5, 3);  // pyramid floor (apex up), 4 triangles
  v << 0, 0, 0, box, 0, 0, box, box, 0, 0, box, 0, 0.5 * box, 0.5 * box, 0.1 * box;
  TriangleMesh::Triangles t(4, 3);
  t << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  sys.add_mesh(v, t, m);
  return sys;
}

bool same_state(const System& a, const System& b) {
  const Particles& p = a.particles();
  const Particles& q = b.particles();
  return p.position == q.position && p.velocity == q.velocity &&
         p.angular_velocity == q.angular_velocity && p.force == q.force && p.torque == q.torque &&
         a.vertex_forces(0) == b.vertex_forces(0) && a.wall_force(0) == b.wall_force(0);
}

}  // namespace

TEST_CASE("dem: a state saved after the mesh has left every particle restores and steps on alike",
          "[dem][state]") {
  // The bed settles on the pyramid, then the mesh is lifted away in jumps (each a list build
  // with no particle near it): the mesh contact arrays are laid out for no rows twice, and a
  // saved state must still pass its own consistency check (it once kept the slots of an earlier
  // layout: "the mesh contact rows do not agree").
  System sys = falling_bed(6e-3, 0.6, 5);
  const double dt = 0.2 * sys.rayleigh_time_step();
  double pressed = 0.0;  // the largest force on the mesh while the bed settles
  for (int k = 0; k < 20; ++k) {
    sys.run(100, dt);
    pressed = std::max(pressed, sys.mesh_force(0).norm());
  }
  REQUIRE(pressed > 0.0);
  Eigen::MatrixX3d x(5, 3);
  for (int k = 0; k < 5; ++k) x.row(k) = sys.mesh(0).positions()[k].transpose();
  for (int jump = 1; jump <= 4; ++jump) {
    Eigen::MatrixX3d y = x;
    y.col(2).array() -= 0.05 * jump;  // far below the box floor
    sys.set_vertex_positions(0, y);
    sys.run(20, dt);
  }
  CHECK(sys.mesh_force(0).norm() == 0.0);
  const SystemState saved = sys.save_state();
  System copy = sys;
  sys.run(50, dt);
  REQUIRE_NOTHROW(copy.restore_state(saved));
  copy.run(50, dt);
  CHECK(same_state(sys, copy));
}

TEST_CASE("dem: restoring a saved state continues bit-identically", "[dem][state]") {
  System sys = falling_bed(6e-3, 0.6, 5);
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(1500, dt);
  const SystemState saved = sys.save_state();
  // move the mesh in the window, as a coupling would
  Eigen::MatrixX3d x(5, 3);
  for (int k = 0; k < 5; ++k) x.row(k) = sys.mesh(0).positions()[k].transpose();
  auto window = [&](System& s) {
    for (int k = 0; k < 300; ++k) {
      Eigen::MatrixX3d y = x;
      y(4, 2) += 1e-6 * k;
      s.set_vertex_positions(0, y);
      s.step(dt);
    }
  };
  window(sys);
  System first = sys;  // copy of the state after the window
  sys.restore_state(saved);
  CHECK(sys.time() == saved.time());
  window(sys);
  CHECK(sys.mesh_force(0).norm() > 0.0);
  CHECK(sys.contact_count() > 0);
  CHECK(same_state(sys, first));
  System other = falling_bed(6e-3, 0.6, 6);
  other.add_particle({1e-3, 1e-3, 5e-3}, 1e-4, 0);
  CHECK_THROWS_AS(other.restore_state(saved), Error);
}

TEST_CASE("dem: identical runs write identical state bytes", "[dem][state]") {
  // A state is written as raw arrays: a mesh contact row's free slots and a record's padding once
  // went out as whatever the heap held (restart files of two identical runs differed). The heap
  // is filled with a different pattern before each run, so such bytes would differ.
  auto run = [](unsigned char fill) {
    {
      std::vector<std::vector<unsigned char>> junk;
      for (int k = 0; k < 4000; ++k) junk.emplace_back(64 + 16 * (k % 64), fill);
    }
    System sys = falling_bed(6e-3, 0.6, 5);
    sys.run(1500, 0.2 * sys.rayleigh_time_step());
    REQUIRE(sys.mesh_force(0).norm() > 0.0);
    std::ostringstream out;
    sys.write_state(out);
    return out.str();
  };
  const std::string a = run(0x00), b = run(0xa5);
  REQUIRE(a.size() == b.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k) differing += a[k] != b[k] ? 1 : 0;
  CHECK(differing == 0);
}

namespace {

// A falling bed (falling_bed(box, 0.6, seed)) after `steps` steps on 1, 2 and 3 threads (3: a
// middle part with pairs crossing into and out of it).
std::array<System, 3> falling_on_threads(double box, std::uint64_t seed, long steps) {
  const int before = max_threads();
  auto run = [&](int threads) {
    set_num_threads(threads);
    System sys = falling_bed(box, 0.6, seed);
    sys.run(steps, 0.2 * sys.rayleigh_time_step());
    return sys;
  };
  std::array<System, 3> out = {run(1), run(2), run(3)};
  set_num_threads(before);
  return out;
}

}  // namespace

TEST_CASE("dem: results do not depend on the number of threads", "[dem][threads]") {
  // > 1024 particles so that the parallel loops run in parallel
  const auto [one, two, three] = falling_on_threads(14e-3, 9, 200);
  INFO(one.particle_count() << " particles");
  CHECK(one.particle_count() > 1024);
  CHECK(same_state(one, two));
  CHECK(same_state(one, three));
  CHECK(one.kinetic_energy() == two.kinetic_energy());
  CHECK(one.kinetic_energy() == three.kinetic_energy());
}

TEST_CASE("dem: a bed of 20 thousand particles gives the same bits on 1 2 and 3 threads",
          "[dem][threads]") {
  // above parallel_pass_min: the list builds' passes over every particle (bounds, cells, plane
  // masks), the copies and the monitors run on the threads too
  const auto [one, two, three] = falling_on_threads(33e-3, 4, 100);
  INFO(one.particle_count() << " particles");
  CHECK(one.particle_count() > static_cast<std::size_t>(parallel_pass_min));
  CHECK(one.neighbor_list().build_count() > 1);  // rebuilt while falling
  CHECK(same_state(one, two));
  CHECK(same_state(one, three));
  CHECK(one.kinetic_energy() == two.kinetic_energy());
  CHECK(one.kinetic_energy() == three.kinetic_energy());
  CHECK(one.contact_count() == two.contact_count());
  CHECK(one.contact_count() == three.contact_count());
  CHECK(one.wall_force(0) == three.wall_force(0));
}

TEST_CASE("dem: user errors throw partita::dem::Error with the value", "[dem][errors]") {
  System sys;
  CHECK_THROWS_WITH(sys.add_particle({0, 0, 0}, 1e-3, 0), Catch::Contains("unknown material id 0"));
  CHECK_THROWS_AS(sys.add_material({-1.0, 0.3, 1000.0}), Error);
  CHECK_THROWS_WITH(sys.add_material({1e7, 0.6, 1000.0}), Catch::Contains("0.6"));
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  CHECK_THROWS_WITH(sys.add_particle({0, 0, 0}, -1e-3, m), Catch::Contains("-0.001"));
  CHECK_THROWS_WITH(sys.add_particle({0, 0, 0}, 1e-3, 3), Catch::Contains("unknown material id 3"));
  CHECK_THROWS_AS(sys.add_interaction(m, m, {0.3, 1.5, 0.0}), Error);
  sys.add_particle({0, 0, 0}, 1e-3, m);
  // (one particle never touches itself: its material needs an interaction only with a second)
  sys.add_particle({0.01, 0, 0}, 1e-3, m);
  CHECK_THROWS_WITH(sys.step(1e-6), Catch::Contains("add_interaction(0, 0"));
  sys.add_interaction(m, m, {0.3, 0.5, 0.0});
  const double dt_r = sys.rayleigh_time_step();
  CHECK_THROWS_WITH(sys.step(1.5 * dt_r), Catch::Contains("above the Rayleigh time step"));
  CHECK_THROWS_AS(sys.step(-1.0), Error);
  CHECK_NOTHROW(sys.step(0.2 * dt_r));
  CHECK_THROWS_AS(sys.wall_force(0), Error);
  CHECK_THROWS_AS(sys.vertex_forces(0), Error);
  Eigen::MatrixX3d v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  TriangleMesh::Triangles t(1, 3);
  t << 0, 1, 5;
  CHECK_THROWS_WITH(sys.add_mesh(v, t, m), Catch::Contains("vertex 5"));
  t << 0, 1, 2;
  const int mesh = sys.add_mesh(v, t, m);
  CHECK_THROWS_AS(sys.set_vertex_positions(mesh, Eigen::MatrixX3d::Zero(4, 3)), Error);
  CHECK_THROWS_AS(LammpsData::read("/nonexistent/bed.data"), Error);
}

TEST_CASE("dem: Rayleigh time step", "[dem]") {
  // the peer bed: R = 1.25 mm, E = 200 MPa, nu = 0.23, rho = 400 -> 9.529e-6 s (RESULTS.md)
  System sys;
  const int m = sys.add_material({2.0e8, 0.23, 400.0});
  sys.add_particle({0, 0, 0}, 2.0e-3, m);
  sys.add_particle({1, 0, 0}, 1.25e-3, m);
  CHECK(sys.rayleigh_time_step() == Approx(9.529e-6).epsilon(1e-3));
}

TEST_CASE("dem: reads the peer bed file", "[dem][io]") {
  const std::string path =
      std::string(PARTITA_SOURCE_DIR) + "/../shared/bench/peers/dem/data/bed_small.data";
  if (!std::filesystem::exists(path)) {
    WARN("peer data not found at " << path << "; skipped");
    return;
  }
  const LammpsData d = LammpsData::read(path);
  CHECK(d.size() == 2001);
  CHECK(d.id[0] == 1);
  CHECK(d.diameter[0] == 0.004);
  CHECK(d.density[1] == 400.0);
  CHECK(d.position[0].x() == Approx(0.001999545126));
  CHECK(d.velocity[0].x() == Approx(-3.29134e-09));
  CHECK(d.angular_velocity[1].z() == Approx(-6.14662e-05));
  CHECK(d.box_hi.x() == Approx(0.021));
}

TEST_CASE("dem: changes made between steps take effect and are seen at once", "[dem][state]") {
  // The moving state lives in the solver's packed arrays while stepping; particles() must show
  // it after every step, and set_particle_velocity()/add_particle() between steps must be used.
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.0});
  sys.add_particle({0, 0, 0}, 1e-3, m, {0.5, 0, 0});
  sys.add_particle({0.1, 0, 0}, 1e-3, m);
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(10, dt);
  // free flight: x = v t
  CHECK(sys.particles().position[0].x() == Approx(0.5 * 10 * dt).epsilon(1e-12));
  sys.set_particle_velocity(0, {0, 2.0, 0}, {0, 0, 3.0});
  CHECK(sys.particles().velocity[0] == Eigen::Vector3d(0, 2.0, 0));
  const Eigen::Vector3d x0 = sys.particles().position[0];
  sys.step(dt);
  CHECK((sys.particles().position[0] - (x0 + dt * Eigen::Vector3d(0, 2.0, 0))).norm() < 1e-15);
  CHECK(sys.particles().angular_velocity[0].z() == 3.0);
  const Eigen::Vector3d x1 = sys.particles().position[1];
  sys.add_particle({0.2, 0, 0}, 1e-3, m, {-1.0, 0, 0});
  CHECK(sys.particles().position[1] == x1);
  CHECK(sys.particles().position[0].y() > 0.0);
  sys.step(dt);
  CHECK(sys.particles().position[2].x() == Approx(0.2 - dt).epsilon(1e-12));
  CHECK(sys.kinetic_energy() > 0.5 * sys.particles().mass[2] * 1.0 * 0.999);
}

namespace {

// Position, force and torque of each particle by id.
struct ById {
  std::map<std::int64_t, Eigen::Vector3d> x, f, t;
  explicit ById(const System& s) {
    const Particles& p = s.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      x[p.id[i]] = p.position[i];
      f[p.id[i]] = p.force[i];
      t[p.id[i]] = p.torque[i];
    }
  }
};

double largest_difference(const std::map<std::int64_t, Eigen::Vector3d>& a,
                          const std::map<std::int64_t, Eigen::Vector3d>& b) {
  double d = 0.0;
  for (const auto& [id, v] : a) d = std::max(d, (v - b.at(id)).norm());
  return d;
}

}  // namespace

TEST_CASE("dem: renumbering the particles in cell order keeps the state and contact histories",
          "[dem][state]") {
  // the bed numbered backwards: far from cell order
  System a = falling_bed(6e-3, 0.6, 5, true);
  const double dt = 0.2 * a.rayleigh_time_step();
  a.run(1500, dt);  // settled: many sticking contacts with tangential history
  System b = a;
  b.sort_particles();
  REQUIRE(b.sort_count() == 1);
  CHECK(b.particles().id != a.particles().id);  // renumbered
  {
    const ById pa(a), pb(b);  // the same state, other numbering
    CHECK(largest_difference(pa.x, pb.x) == 0.0);
    CHECK(largest_difference(pa.f, pb.f) == 0.0);
  }
  a.step(dt);
  b.step(dt);
  const ById pa(a), pb(b);
  double f_max = 0.0, t_max = 0.0;
  for (const auto& [id, f] : pa.f) f_max = std::max(f_max, f.norm());
  for (const auto& [id, t] : pa.t) t_max = std::max(t_max, t.norm());
  // the sums run in another order: equal to round-off; a lost tangential history would change
  // the friction forces and torques by a fraction of mu F_n
  CHECK(largest_difference(pa.f, pb.f) < 1e-12 * f_max);
  CHECK(largest_difference(pa.t, pb.t) < 1e-12 * t_max);
  CHECK(a.mesh_force(0).isApprox(b.mesh_force(0), 1e-12));
  CHECK(a.wall_force(0).isApprox(b.wall_force(0), 1e-12));
  CHECK(a.contact_count() == b.contact_count());
}

TEST_CASE("dem: sorting at list builds follows the same motion and restores bit-identically",
          "[dem][state]") {
  System a = falling_bed(6e-3, 0.6, 5, true);
  System b = a;
  const double dt = 0.2 * a.rayleigh_time_step();
  a.run(600, dt);  // falling and landing
  b.run(100, dt);
  b.set_sort_interval(1);  // the next list build inside a step renumbers the backward bed
  b.run(500, dt);
  INFO(b.sort_count() << " sorts in " << b.neighbor_list().build_count() << " list builds");
  CHECK(b.sort_count() >= 1);
  const ById pa(a), pb(b);
  // round-off differences only (summation order), grown over 600 steps of a few contacts
  CHECK(largest_difference(pa.x, pb.x) < 1e-9);
  // restore with sorting on: the count of builds since the last sort is part of the state
  b.set_sort_interval(3);
  const SystemState saved = b.save_state();
  b.run(300, dt);
  System first = b;
  b.restore_state(saved);
  b.run(300, dt);
  CHECK(same_state(b, first));
  CHECK_THROWS_AS(b.set_sort_interval(-1), Error);
}
