// One-sided mesh contacts (TriangleMesh::one_sided()): the closed surface of a body, triangles
// counter-clockwise seen from outside. A sphere whose centre has passed behind a face is pushed
// back out along the outward normal with the overlap r - s (s its signed distance to the plane),
// where two-sided contacts push it on into (and through) a thin plate; outside the body both
// give the same contact.

#include "dem_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace partita::dem;

namespace {

constexpr double E = 1.0e8, NU = 0.3, RHO = 2500.0, R = 1.0e-3;

// The closed slab [-L, L]^2 x [-T, 0], 12 triangles counter-clockwise seen from outside.
void slab(double L, double T, Eigen::MatrixX3d& v, TriangleMesh::Triangles& t) {
  v.resize(8, 3);
  for (int k = 0; k < 8; ++k)
    v.row(k) << ((k & 1) ? L : -L), ((k & 2) ? L : -L), ((k & 4) ? 0.0 : -T);
  // each side as 4 corners counter-clockwise seen from outside
  const int quads[6][4] = {{4, 5, 7, 6},   // top z = 0
                           {0, 2, 3, 1},   // bottom z = -T
                           {0, 1, 5, 4},   // y = -L
                           {2, 6, 7, 3},   // y = +L
                           {0, 4, 6, 2},   // x = -L
                           {1, 3, 7, 5}};  // x = +L
  t.resize(12, 3);
  for (int q = 0; q < 6; ++q) {
    t.row(2 * q) << quads[q][0], quads[q][1], quads[q][2];
    t.row(2 * q + 1) << quads[q][0], quads[q][2], quads[q][3];
  }
}

struct Run {
  System sys;
  int mesh;
};

Run slab_run(double T, bool one_sided, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
             double restitution = 1.0, double friction = 0.0) {
  Run run{test::single_material(E, NU, RHO, restitution, friction), -1};
  run.sys.add_particle(x, R, 0, v);
  Eigen::MatrixX3d vertices;
  TriangleMesh::Triangles triangles;
  slab(10.0 * R, T, vertices, triangles);
  run.mesh = run.sys.add_mesh(vertices, triangles, 0);
  run.sys.set_mesh_one_sided(run.mesh, one_sided);
  return run;
}

double e_star() {
  return E / (2.0 * (1.0 - NU * NU));
}
double hertz_force(double delta) {
  return 4.0 / 3.0 * e_star() * std::sqrt(R) * std::pow(delta, 1.5);
}
double hertz_energy(double delta) {
  return 8.0 / 15.0 * e_star() * std::sqrt(R) * std::pow(delta, 2.5);
}

}  // namespace

TEST_CASE("dem one-sided mesh: the slab's triangles face outward (the set-up of these tests)",
          "[dem][mesh][one_sided]") {
  Eigen::MatrixX3d v;
  TriangleMesh::Triangles t;
  slab(10.0 * R, 2.0 * R, v, t);
  const TriangleMesh m(v, t, 0);
  const Eigen::Vector3d centre(0.0, 0.0, -R);
  for (int k = 0; k < m.triangle_count(); ++k) {
    const auto& tri = m.triangle(k);
    const Eigen::Vector3d c =
        (m.positions()[tri[0]] + m.positions()[tri[1]] + m.positions()[tri[2]]) / 3.0;
    CHECK(m.normal(k).dot(c - centre) > 0.0);
  }
}

TEST_CASE("dem one-sided mesh: a centre behind a face is pushed back out with overlap r + depth",
          "[dem][mesh][one_sided]") {
  // A sphere at rest whose centre lies 0.3 R inside a slab 2 R thick (the bottom face 1.7 R
  // away, beyond reach): one-sided, the top face pushes it up with the Hertz force of the
  // overlap 1.3 R, and it leaves with the elastic energy of that overlap (no damping, no
  // friction: the contact law is conservative along the fixed normal).
  const double depth = 0.3 * R, delta0 = R + depth;
  Run run = slab_run(2.0 * R, true, {2.1 * R, -1.3 * R, -depth}, Eigen::Vector3d::Zero());
  CHECK(run.sys.elastic_energy() == Approx(hertz_energy(delta0)).epsilon(1e-12));
  const double dt = 0.002 * run.sys.rayleigh_time_step();
  run.sys.step(dt);
  const Eigen::Vector3d f = run.sys.mesh_force(run.mesh);  // on the mesh: -(force on sphere)
  CHECK(f.z() == Approx(-hertz_force(delta0)).epsilon(1e-3));
  CHECK(std::abs(f.x()) < 1e-12 * std::abs(f.z()));
  CHECK(std::abs(f.y()) < 1e-12 * std::abs(f.z()));
  for (int s = 0; s < 20000 && run.sys.particles().position[0].z() < 2.0 * R; ++s) run.sys.step(dt);
  const auto& p = run.sys.particles();
  REQUIRE(p.position[0].z() >= 2.0 * R);  // out, above the slab
  const double m = test::sphere_mass(R, RHO);
  CHECK(0.5 * m * p.velocity[0].squaredNorm() == Approx(hertz_energy(delta0)).epsilon(5e-3));
  CHECK(std::abs(p.velocity[0].x()) < 1e-9 * p.velocity[0].z());

  // Inside a plate R thick, 0.7 R below its top: both faces are within reach and it is behind
  // both; it leaves through the nearer one (the bottom, 0.3 R away) with the energy of 1.3 R.
  Run thin = slab_run(R, true, {2.1 * R, -1.3 * R, -0.7 * R}, Eigen::Vector3d::Zero());
  CHECK(thin.sys.elastic_energy() == Approx(hertz_energy(delta0)).epsilon(1e-12));
  for (int s = 0; s < 20000 && thin.sys.particles().position[0].z() > -3.0 * R; ++s)
    thin.sys.step(dt);
  const auto& pt = thin.sys.particles();
  REQUIRE(pt.position[0].z() <= -3.0 * R);  // out, below the plate
  CHECK(0.5 * m * pt.velocity[0].squaredNorm() == Approx(hertz_energy(delta0)).epsilon(5e-3));

  // Two-sided (the default), the same start is pushed down into the slab and stays inside it
  // (top and bottom faces both push toward its middle): the defect one-sided contacts remove.
  Run two = slab_run(2.0 * R, false, {2.1 * R, -1.3 * R, -depth}, Eigen::Vector3d::Zero());
  two.sys.step(dt);
  CHECK(two.sys.mesh_force(two.mesh).z() > 0.0);  // the sphere pushed down
  double z_max = -depth;
  for (int s = 0; s < 20000; ++s) {
    two.sys.step(dt);
    z_max = std::max(z_max, two.sys.particles().position[0].z());
  }
  CHECK(z_max < 0.0);
}

TEST_CASE("dem one-sided mesh: a fast sphere rebounds from a plate thinner than its radius",
          "[dem][mesh][one_sided]") {
  // The speed at which the Hertz overlap would reach 1.2 R (Hertz impact theory, mesh R* = R,
  // m* = m): the centre crosses the top face of a 0.5 R plate (to 0.2 R deep, less than half the
  // plate, and the bottom face is within reach throughout). One-sided, it comes back with the
  // speed it came in (no damping) after Hertz's deepest overlap; two-sided, it leaves below.
  const double T = 0.5 * R;
  const double m = test::sphere_mass(R, RHO);
  const double delta_max = 1.2 * R;
  const double v0 =
      std::sqrt(16.0 * e_star() * std::sqrt(R) * std::pow(delta_max, 2.5) / (15.0 * m));
  const test::HertzImpact theory(m, R, e_star(), v0);
  REQUIRE(theory.delta_max == Approx(delta_max).epsilon(1e-12));
  const Eigen::Vector3d x0(0.7 * R, 0.4 * R, 1.01 * R);
  for (bool one_sided : {true, false}) {
    Run run = slab_run(T, one_sided, x0, {0.0, 0.0, -v0});
    const double dt = 0.002 * run.sys.rayleigh_time_step();
    double z_min = x0.z();
    for (int s = 0; s < 200000; ++s) {
      run.sys.step(dt);
      const double z = run.sys.particles().position[0].z();
      z_min = std::min(z_min, z);
      if (z > 1.5 * R || z < -T - 1.5 * R) break;
    }
    const auto& p = run.sys.particles();
    if (one_sided) {
      INFO("one-sided");
      CHECK(p.position[0].z() > 1.5 * R);
      CHECK(p.velocity[0].z() == Approx(v0).epsilon(2e-3));
      CHECK(R - z_min == Approx(delta_max).epsilon(2e-3));  // the deepest overlap, as Hertz's
    } else {
      INFO("two-sided");
      CHECK(p.position[0].z() < -T - 1.5 * R);
      CHECK(p.velocity[0].z() < 0.0);
    }
  }
}

TEST_CASE("dem one-sided mesh: outside the body the contacts are the two-sided ones",
          "[dem][mesh][one_sided]") {
  // Drops with damping and friction onto the top face, a top edge and a corner of the slab:
  // every contact from outside, where both definitions agree (the face's normal equals centre -
  // closest point up to rounding).
  const double L = 10.0 * R;
  const Eigen::Vector3d starts[] = {{2.1 * R, -1.3 * R, 1.01 * R},         // face
                                    {L + 0.5 * R, 0.3 * R, 1.0 * R},       // edge x = L, z = 0
                                    {L + 0.4 * R, L + 0.5 * R, 0.9 * R}};  // corner
  for (const Eigen::Vector3d& x0 : starts) {
    Eigen::Vector3d v_end[2], w_end[2];
    for (int k = 0; k < 2; ++k) {
      Run run = slab_run(2.0 * R, k == 0, x0, {0.1, 0.05, -0.5}, 0.5, 0.4);
      const double dt = 0.05 * run.sys.rayleigh_time_step();
      for (int s = 0; s < 4000; ++s) run.sys.step(dt);
      v_end[k] = run.sys.particles().velocity[0];
      w_end[k] = run.sys.particles().angular_velocity[0];
    }
    INFO("start " << x0.transpose() / R << " R");
    CHECK((v_end[0] - Eigen::Vector3d(0.1, 0.05, -0.5)).norm() > 0.1);  // it touched
    CHECK((v_end[0] - v_end[1]).norm() < 1e-9 * v_end[1].norm());
    CHECK((w_end[0] - w_end[1]).norm() < 1e-9 * (w_end[1].norm() + v_end[1].norm() / R));
  }
}

TEST_CASE("dem mesh: a face that enters the contacts under a particle does not throw it out",
          "[dem][mesh][one_sided]") {
  // A face exposed by erosion under a particle that sat where the eroded material was: the
  // particle overlaps it by 0.6 R at once. Its contact keeps that overlap as its pre-overlap and
  // pushes only beyond it: the particle stays (no launch; with the whole overlap it would leave
  // at the speed of Hertz's energy of 0.6 R), is resisted when driven further in, and leaves
  // the pre-overlap behind as it moves out (a later approach is an ordinary contact).
  for (bool one_sided : {false, true}) {
    INFO((one_sided ? "one-sided" : "two-sided"));
    Run run = slab_run(2.0 * R, one_sided, {2.1 * R, -1.3 * R, 0.4 * R}, Eigen::Vector3d::Zero(),
                       0.5, 0.3);
    for (int t = 0; t < 12; ++t) run.sys.set_triangle_active(run.mesh, t, false);
    const double dt = 0.01 * run.sys.rayleigh_time_step();
    run.sys.step(dt);  // nothing to touch
    for (int t = 0; t < 12; ++t) run.sys.set_triangle_active(run.mesh, t, true);
    for (int s = 0; s < 2000; ++s) run.sys.step(dt);
    const double m = test::sphere_mass(R, RHO);
    const auto v0 = [&] { return run.sys.particles().velocity[0]; };
    const auto z0 = [&] { return run.sys.particles().position[0].z(); };
    CHECK(v0().norm() < 1e-6);  // (the whole overlap would launch it at 39 m/s)
    CHECK(std::abs(z0() - 0.4 * R) < 1e-9);
    CHECK(run.sys.elastic_energy() < 1e-12);  // (Hertz at 0.6 R: 8 mJ)
    // driven further in at 0.05 m/s: pushed back by the overlap beyond 0.6 R alone (Hertz's
    // deepest overlap at that speed, within the damping's effect), out at less than its speed in
    run.sys.set_particle_velocity(0, Eigen::Vector3d(0.0, 0.0, -0.05));
    double z_min = z0();
    for (int s = 0; s < 3000; ++s) {
      run.sys.step(dt);
      z_min = std::min(z_min, z0());
    }
    const double delta_beyond = 0.4 * R - z_min;
    const test::HertzImpact hertz(m, R, e_star(), 0.05);
    CHECK(v0().z() > 0.0);
    CHECK(delta_beyond > 0.5 * hertz.delta_max);
    CHECK(delta_beyond < 1.01 * hertz.delta_max);
    CHECK(v0().norm() < 0.05);
  }
}

TEST_CASE("dem one-sided mesh: a centre that comes within r of a face from deep inside the body "
          "is not thrown out",
          "[dem][mesh][one_sided][energy]") {
  // A sphere whose centre lies 1.1 R inside a slab 4 R thick (no face within r: no contact)
  // moves toward the top face at 0.2 m/s, as a granule left inside a body by erosion does. When
  // its centre comes within r of the face, the contact appears with an overlap of almost 2 R that
  // no motion made: it is a pre-overlap, followed down as the sphere moves out. The sphere
  // leaves at its own speed (pushed with the whole overlap it would take Hertz's energy of 2 R,
  // 0.17 J, about 10^6 times its kinetic energy), no force acts, and the energy books close (nothing
  // created).
  const double v0 = 0.2;
  Run run = slab_run(4.0 * R, true, {2.1 * R, -1.3 * R, -1.1 * R}, {0.0, 0.0, v0});
  run.sys.set_energy_tracking(true);
  const double dt = 0.05 * run.sys.rayleigh_time_step();
  double f_max = 0.0;
  int s = 0;
  for (; s < 100000 && run.sys.particles().position[0].z() < 2.0 * R; ++s) {
    run.sys.step(dt);
    f_max = std::max(f_max, run.sys.mesh_force(run.mesh).norm());
  }
  const auto& p = run.sys.particles();
  INFO("steps " << s << ", largest force " << f_max << " N (Hertz at R: " << hertz_force(R)
                << " N), speed out " << p.velocity[0].transpose() << " m/s, balance "
                << run.sys.energy_balance_error());
  REQUIRE(p.position[0].z() >= 2.0 * R);  // out, above the slab
  CHECK(f_max < 1e-6 * hertz_force(R));
  CHECK(p.velocity[0].z() == Approx(v0).epsilon(1e-5));  // (the float pre-overlap's rounding)
  CHECK(std::abs(run.sys.energy_balance_error()) < 1e-5);
  // The same sphere placed there at the start (the first pass: its overlap is the initial
  // elastic energy) is pushed out with it, as a centre behind a face always is at the start.
  Run start = slab_run(4.0 * R, true, {2.1 * R, -1.3 * R, -0.9 * R}, Eigen::Vector3d::Zero());
  start.sys.step(0.002 * start.sys.rayleigh_time_step());
  CHECK(start.sys.elastic_energy() > 0.9 * hertz_energy(1.9 * R));
  CHECK(-start.sys.mesh_force(start.mesh).z() == Approx(hertz_force(1.9 * R)).epsilon(1e-3));
}
