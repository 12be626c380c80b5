// The DEM's energy accounting (System::energies(), energy_balance_error()) on cases with a
// closed-form answer: friction work of a sphere that slides into rolling, damping work of an
// impact, the work of a moving mesh, a change of the particle set, and the balance of a packing
// compressed by a mesh under gravity (the same bits on 1 and 2 threads).

#include "dem_test_helpers.hpp"

#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <tuple>

using namespace partita::dem;

namespace {

constexpr double E = 1.0e8, NU = 0.25, RHO = 2500.0, R = 1.0e-3;

// A square of 2 x 2 cells (8 triangles) of side `size` centred on (cx, cy) at height z.
void square(double size, double cx, double cy, double z, Eigen::MatrixX3d& v,
            TriangleMesh::Triangles& t) {
  v.resize(9, 3);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      v.row(3 * j + i) << cx + (i - 1) * 0.5 * size, cy + (j - 1) * 0.5 * size, z;
  t.resize(8, 3);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i, k = 2 * (2 * j + i);
      t.row(k) << a, a + 1, a + 4;
      t.row(k + 1) << a, a + 4, a + 3;
    }
}

// One material, no gravity, the energy accounting on.
System energy_system(double restitution, double friction) {
  System sys = test::single_material(E, NU, RHO, restitution, friction);
  sys.set_energy_tracking(true);
  return sys;
}

}  // namespace

TEST_CASE("dem energy: a sphere sliding on a plane loses 2/7 of its kinetic energy to friction",
          "[dem][energy]") {
  // Thrown without spin along a plane with friction mu: it slides until v = 5/7 v0 and rolls on;
  // the friction work is 1/2 m v0^2 - (1/2 m v^2 + 1/2 I w^2) = 2/7 (1/2 m v0^2).
  const double mu = 0.3, v0 = 0.2, g = 9.81;
  System sys = energy_system(0.5, mu);
  sys.set_gravity({0, 0, -g});
  const double m = test::sphere_mass(R, RHO);
  const double e_star = E / (2.0 * (1.0 - NU * NU));  // sphere on a plane of its material
  const double delta0 = std::pow(m * g / (4.0 / 3.0 * e_star * std::sqrt(R)), 2.0 / 3.0);
  sys.add_particle({0, 0, R - delta0}, R, 0, {v0, 0, 0});
  sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  const double dt = 0.1 * sys.rayleigh_time_step();
  // sliding lasts 2 v0 / (7 mu g) = 19.4 ms
  const double t_slide = 2.0 * v0 / (7.0 * mu * g);
  sys.run(static_cast<long>(1.5 * t_slide / dt), dt);
  const double ke0 = 0.5 * m * v0 * v0;
  const auto& en = sys.energies();
  INFO("v = " << sys.particles().velocity[0].x() << " m/s (5/7 v0 = " << 5.0 / 7.0 * v0
              << "), friction work " << en.friction << " J, 2/7 KE0 = " << 2.0 / 7.0 * ke0
              << " J, damping " << en.damping << " J, balance error "
              << sys.energy_balance_error());
  CHECK(sys.particles().velocity[0].x() == Approx(5.0 / 7.0 * v0).epsilon(1e-3));
  CHECK(en.friction == Approx(2.0 / 7.0 * ke0).epsilon(2e-3));
  CHECK(en.damping < 1e-3 * ke0);
  CHECK(std::abs(sys.energy_balance_error()) < 1e-4);
}

TEST_CASE("dem energy: an impact with restitution e dissipates 1/2 m v^2 (1 - e^2) by damping",
          "[dem][energy]") {
  const double v = 0.5;
  for (const double e : {0.3, 0.5, 0.8}) {
    System sys = energy_system(e, 0.0);
    const double m = test::sphere_mass(R, RHO);
    sys.add_particle({0, 0, R + 1e-6}, R, 0, {0, 0, -v});
    const int wall = sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
    const double dt = sys.time_step_fraction() * sys.rayleigh_time_step();
    sys.run(static_cast<long>(2e-6 / (v * dt)) + 2000, dt);  // the contact lasts ~ 100 steps
    const double v_out = sys.particles().velocity[0].z();
    const auto& en = sys.energies();
    INFO("e = " << e << ": rebound " << v_out / v << ", damping work " << en.damping
                << " J, 1/2 m v^2 (1 - e^2) = " << 0.5 * m * v * v * (1 - e * e) << " J");
    CHECK(sys.wall_force(wall).norm() == 0.0);  // the contact is over
    // against the law (e realised to 1 %: 1 - e^2 to 2 %) and against the rebound measured
    CHECK(en.damping == Approx(0.5 * m * v * v * (1.0 - e * e)).epsilon(0.02));
    CHECK(en.damping == Approx(0.5 * m * (v * v - v_out * v_out)).epsilon(1e-3));
    CHECK(en.friction == 0.0);
    CHECK(std::abs(sys.energy_balance_error()) < 1e-3);
  }
}

TEST_CASE("dem energy: a mesh pressing a sphere onto a plane does the work stored and dissipated",
          "[dem][energy]") {
  // A flat mesh moves down at constant V onto a sphere resting on a plane, no gravity: its work
  // goes into the two Hertz contacts (in series, force F: E_el = sum 2/5 F delta_k) and their
  // damping (small at V << impact speeds); the balance closes.
  System sys = energy_system(0.5, 0.3);
  sys.add_particle({0, 0, R}, R, 0);
  sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  Eigen::MatrixX3d x;
  TriangleMesh::Triangles t;
  square(4 * R, 0.0, 0.0, 2 * R + 1e-6, x, t);
  const int mesh = sys.add_mesh(x, t, 0);
  const double dt = 0.1 * sys.rayleigh_time_step();
  const double V = 1e-3;
  const long steps = static_cast<long>(2e-5 / (V * dt));  // 20 um of travel, ~19 um of overlap
  const Eigen::MatrixX3d x0 = x;
  for (long s = 1; s <= steps; ++s) {
    x.col(2) = x0.col(2).array() - V * dt * static_cast<double>(s);
    sys.set_vertex_positions(mesh, x);
    sys.step(dt);
  }
  const double F = sys.mesh_force(mesh).z();
  const double e_star = E / (2.0 * (1.0 - NU * NU));
  const double delta = std::pow(F / (4.0 / 3.0 * e_star * std::sqrt(R)), 2.0 / 3.0);
  const double stored = 2.0 * 0.4 * F * delta;  // two equal contacts
  const auto& en = sys.energies();
  INFO("mesh force " << F << " N, overlap " << delta << " m, mesh work " << en.mesh_work[0]
                     << " J, 2 x 2/5 F delta = " << stored << " J, damping " << en.damping
                     << " J, kinetic " << sys.kinetic_energy() << " J, balance error "
                     << sys.energy_balance_error());
  REQUIRE(F > 0.0);
  CHECK(en.mesh_work[0] == Approx(stored + en.damping + en.friction).epsilon(2e-3));
  CHECK(en.mesh_work[0] == Approx(stored).epsilon(0.02));
  CHECK(en.wall_work[0] == 0.0);  // the plane stands still
  CHECK(std::abs(sys.energy_balance_error()) < 1e-3);
}

TEST_CASE("dem energy: a particle replaced by lighter fragments takes their missing energy along",
          "[dem][energy]") {
  // A free sphere at v is replaced (between steps) by two inscribed half-radius spheres at the
  // same velocity: 1/4 of the mass stays, 3/4 m v^2 / 2 leaves with the change (breakage).
  System sys = energy_system(0.5, 0.3);
  const Eigen::Vector3d v(0.3, -0.1, 0.2);
  sys.add_particle({0, 0, 0}, R, 0, v);
  sys.add_particle({5 * R, 0, 0}, R, 0);  // a bystander at rest
  const double dt = 0.1 * sys.rayleigh_time_step();
  sys.run(10, dt);
  const Eigen::Vector3d x = sys.particles().position[0];
  const Eigen::Vector3d vx = sys.particles().velocity[0];
  sys.remove_particles({1, 0});
  sys.add_particle(x + Eigen::Vector3d(0.5 * R, 0, 0), 0.5 * R, 0, vx);
  sys.add_particle(x - Eigen::Vector3d(0.5 * R, 0, 0), 0.5 * R, 0, vx);
  sys.run(10, dt);
  const double m = test::sphere_mass(R, RHO);
  INFO("breakage " << sys.energies().breakage << " J");
  CHECK(sys.energies().breakage == Approx(0.75 * 0.5 * m * v.squaredNorm()).epsilon(1e-12));
  CHECK(std::abs(sys.energy_balance_error()) < 1e-9);
}

TEST_CASE("dem energy: a packing compressed by a mesh under gravity balances its energy, on any "
          "thread count",
          "[dem][energy][threads]") {
  const Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi(8e-3, 8e-3, 8e-3);
  // ~100 spheres at 30 % solids fall into an open box; a flat mesh lid comes down 3.4 mm over
  // 30,000 steps (it meets the settled bed at the end and presses it), then stays 6,000 steps.
  const Packing pk = test::two_size_packing(lo, hi, 1.6e-3, 1.2e-3, 0.7, 11);
  struct Result {
    System::Energies e;
    double error, worst;
  };
  auto run = [&](int threads) {
    const int before = max_threads();
    set_num_threads(threads);
    System sys = energy_system(0.5, 0.4);
    sys.set_gravity({0, 0, -9.81});
    sys.add_particles(pk.positions, pk.radii, 0);
    sys.add_box(lo, hi, 0, 0b011111);
    Eigen::MatrixX3d x;
    TriangleMesh::Triangles t;
    square(hi.x(), 0.5 * hi.x(), 0.5 * hi.y(), hi.z(), x, t);
    const int mesh = sys.add_mesh(x, t, 0);
    const double dt = 0.1 * sys.rayleigh_time_step();
    const Eigen::MatrixX3d x0 = x;
    const long steps = 30000;
    const double V = 3.4e-3 / (static_cast<double>(steps) * dt);
    double worst = 0.0;  // the largest |balance error| at the 12 checks
    for (long s = 1; s <= steps + 6000; ++s) {
      const double z = -V * dt * static_cast<double>(std::min(s, steps));
      x.col(2) = x0.col(2).array() + z;
      sys.set_vertex_positions(mesh, x);
      sys.step(dt);
      if (s % 3000 == 0) worst = std::max(worst, std::abs(sys.energy_balance_error()));
    }
    Result r{sys.energies(), sys.energy_balance_error(), worst};
    set_num_threads(before);
    return r;
  };
  const Result one = run(1);
  const Result two = run(2);
  const System::Energies& e = one.e;
  INFO("mesh work " << e.mesh_work[0] << " J, wall work " << e.wall_work[0] << " J, gravity "
                    << e.gravity << " J, friction " << e.friction << " J, damping " << e.damping
                    << " J, stiffening " << e.stiffening << " J, balance error " << one.error
                    << ", largest at the checks " << one.worst);
  CHECK(e.mesh_work[0] > 0.0);
  CHECK(e.friction > 0.0);
  CHECK(e.damping > 0.0);
  CHECK(one.worst < 1e-3);
  // the same bits on two threads
  CHECK(std::memcmp(&one.e.friction, &two.e.friction, sizeof(double)) == 0);
  CHECK(std::memcmp(&one.e.damping, &two.e.damping, sizeof(double)) == 0);
  CHECK(std::memcmp(&one.e.gravity, &two.e.gravity, sizeof(double)) == 0);
  CHECK(std::memcmp(&one.e.mesh_work[0], &two.e.mesh_work[0], sizeof(double)) == 0);
  CHECK(std::memcmp(&one.error, &two.error, sizeof(double)) == 0);
}

TEST_CASE("dem energy: the energies are part of the saved state", "[dem][energy]") {
  System sys = energy_system(0.5, 0.3);
  sys.set_gravity({0, 0, -9.81});
  sys.add_particle({0, 0, R - 1e-6}, R, 0, {0.1, 0, 0});
  sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  const double dt = 0.1 * sys.rayleigh_time_step();
  sys.run(200, dt);
  const SystemState saved = sys.save_state();
  sys.run(300, dt);
  const System::Energies a = sys.energies();
  sys.restore_state(saved);
  sys.run(300, dt);
  CHECK(sys.energies().friction == a.friction);
  CHECK(sys.energies().damping == a.damping);
  CHECK(sys.energies().gravity == a.gravity);
  CHECK(sys.energies().wall_work == a.wall_work);
  CHECK(a.friction > 0.0);
}

TEST_CASE("dem energy: a sphere pressed into a mesh holds the Hertz energy before the first step, "
          "its face, edge or vertex counted once",
          "[dem][energy][mesh]") {
  // A sphere of radius R pressed by delta into a mesh of its own material (E* = E / (2 (1 -
  // nu^2)), R* = R) stores 8/15 E* sqrt(R) delta^(5/2), the integral of the Hertz force
  // 4/3 E* sqrt(R) d^(3/2) over the overlap. Before the first step no force pass has run (the
  // mesh contacts are found for the energy as the pass will find them); after the first step
  // the accounting's start value holds the first pass's contacts: both give the Hertz energy.
  const double e_star = E / (2.0 * (1.0 - NU * NU)), delta = 1e-5;
  const double hertz = 8.0 / 15.0 * e_star * std::sqrt(R) * std::pow(delta, 2.5);
  const double s = 4 * R;  // the flat square: 2 x 2 cells of side s/2, 8 triangles, at z = 0
  Eigen::MatrixX3d flat;
  TriangleMesh::Triangles flat_t;
  square(s, 0.0, 0.0, 0.0, flat, flat_t);
  // a roof: two faces rising at 1 in 5 to a ridge along y at x = 0 (each face two triangles;
  // the ridge is an edge of one triangle of each face)
  const double L = 4 * R, h = 0.2 * L;
  Eigen::MatrixX3d roof(6, 3);
  roof << -L, -L, 0, 0, -L, h, L, -L, 0, -L, L, 0, 0, L, h, L, L, 0;
  TriangleMesh::Triangles roof_t(4, 3);
  roof_t << 0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4;
  struct Placement {
    const char* what;
    const Eigen::MatrixX3d* vertices;
    const TriangleMesh::Triangles* triangles;
    Eigen::Vector3d point;   // the touching point of the mesh
    Eigen::Vector3d normal;  // from it towards the sphere's centre
  };
  const Eigen::Vector3d up(0, 0, 1);
  const Eigen::Vector3d out = Eigen::Vector3d(-1, -1, 1).normalized();
  const Placement cases[] = {
      {"inside a face", &flat, &flat_t, {-0.1 * s, -0.4 * s, 0}, up},
      {"on the diagonal edge of two coplanar triangles", &flat, &flat_t, {-0.25 * s, -0.25 * s, 0},
       up},
      {"on the edge between two cells", &flat, &flat_t, {0, -0.3 * s, 0}, up},
      {"on the vertex of six coplanar triangles", &flat, &flat_t, {0, 0, 0}, up},
      {"beyond the corner vertex of the square", &flat, &flat_t, {-0.5 * s, -0.5 * s, 0}, out},
      {"on the ridge of a roof (an edge of two faces at an angle)", &roof, &roof_t,
       {0, -0.3 * L, h}, up},
  };
  for (const Placement& c : cases) {
    System sys = energy_system(0.5, 0.3);
    const Eigen::Vector3d centre = c.point + (R - delta) * c.normal;
    sys.add_particle(centre, R, 0);
    sys.add_mesh(*c.vertices, *c.triangles, 0);
    const double before = sys.elastic_energy();
    const double dt = 0.1 * sys.rayleigh_time_step();
    sys.step(dt);
    const double first_pass = sys.energies().elastic_start;
    INFO(c.what << ": elastic energy before the first step " << before << " J, at the first pass "
                << first_pass << " J, Hertz " << hertz << " J");
    CHECK(before == Approx(hertz).epsilon(1e-12));
    CHECK(first_pass == Approx(hertz).epsilon(1e-12));
    CHECK(sys.mesh_force(0).norm() > 0.0);  // (the first pass found the contact too)
  }
}

TEST_CASE("dem energy: the elastic energy before the first step leaves the run as it was",
          "[dem][energy][mesh]") {
  // Asking for the energy before the first step (a scratch search of the contacts) changes
  // nothing in what the steps compute: the same bits with and without the question.
  auto run = [](bool ask) {
    System sys = energy_system(0.5, 0.3);
    sys.set_gravity({0, 0, -9.81});
    const Packing pk = test::two_size_packing(Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d(6e-3, 6e-3, 4e-3), 1.6e-3, 1.2e-3,
                                              0.6, 5);
    sys.add_particles(pk.positions, pk.radii, 0);
    Eigen::MatrixX3d x;
    TriangleMesh::Triangles t;
    square(6e-3, 3e-3, 3e-3, 0.1e-3, x, t);  // a floor that overlaps the lowest spheres
    const int mesh = sys.add_mesh(x, t, 0);
    double e0 = 0.0;
    if (ask) e0 = sys.elastic_energy();
    const double dt = 0.1 * sys.rayleigh_time_step();
    sys.run(200, dt);
    return std::make_tuple(e0, sys.particles().position, sys.mesh_force(mesh),
                           sys.energies().elastic_start);
  };
  const auto [e_asked, x_asked, f_asked, start_asked] = run(true);
  const auto [e_not, x_not, f_not, start_not] = run(false);
  INFO("elastic energy before the first step " << e_asked << " J, at the first pass "
                                               << start_asked << " J");
  CHECK(e_asked > 0.0);
  CHECK(e_asked == Approx(start_asked).epsilon(1e-12));  // the same contacts
  CHECK(start_asked == start_not);
  CHECK(f_asked == f_not);
  REQUIRE(x_asked.size() == x_not.size());
  for (std::size_t i = 0; i < x_asked.size(); ++i) CHECK(x_asked[i] == x_not[i]);
}
