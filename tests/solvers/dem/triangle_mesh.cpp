// Sphere-triangle contacts: same rebound as on a plane wherever the sphere hits a triangulated
// plane (face, shared edge, shared vertex), force distribution to vertices, moving meshes.

#include "dem_test_helpers.hpp"

#include <catch2/catch.hpp>

using namespace partita::dem;

namespace {

constexpr double E = 1.0e8, NU = 0.3, RHO = 2500.0, R = 1.0e-3;

// Coplanar triangulated square [-L, L]^2 at z = 0 with n x n cells, two triangles per cell,
// alternating diagonals so that vertices are shared by 4 or 8 triangles.
void triangulated_plane(double L, int n, Eigen::MatrixX3d& v, TriangleMesh::Triangles& t) {
  v.resize((n + 1) * (n + 1), 3);
  t.resize(2 * n * n, 3);
  const double h = 2.0 * L / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) v.row(j * (n + 1) + i) << -L + i * h, -L + j * h, 0.0;
  int k = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      if ((i + j) % 2 == 0) {
        t.row(k++) << a, b, d;
        t.row(k++) << a, d, c;
      } else {
        t.row(k++) << a, b, c;
        t.row(k++) << b, d, c;
      }
    }
}

struct Bounce {
  Eigen::Vector3d v, w;
  double force_max;
};

// Drops a sphere vertically (with friction and damping on) at (x, y) onto a plane or a mesh.
Bounce bounce(bool on_mesh, double x, double y) {
  System sys = test::single_material(E, NU, RHO, 0.5, 0.4);
  sys.add_particle({x, y, R + 1e-5}, R, 0, {0.0, 0.0, -0.5});
  int mesh = -1, wall = -1;
  if (on_mesh) {
    Eigen::MatrixX3d v;
    TriangleMesh::Triangles t;
    triangulated_plane(4.0 * R, 4, v, t);
    mesh = sys.add_mesh(v, t, 0);
  } else {
    wall = sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
  }
  const double dt = 0.1 * sys.rayleigh_time_step();
  double fmax = 0.0;
  for (int s = 0; s < 4000; ++s) {
    sys.step(dt);
    const Eigen::Vector3d f = on_mesh ? sys.mesh_force(mesh) : sys.wall_force(wall);
    fmax = std::max(fmax, f.norm());
  }
  return {sys.particles().velocity[0], sys.particles().angular_velocity[0], fmax};
}

}  // namespace

TEST_CASE("dem: bounce on a triangulated plane equals bounce on a plane", "[dem][mesh]") {
  // h = 2 mm cells: (0, 0) is a vertex shared by 8 triangles of the alternating pattern, (1 mm, 0)
  // the midpoint of a shared edge, (0.6 mm, 0.3 mm) inside a face, (1 mm, 1 mm) on a diagonal.
  const Bounce ref = bounce(false, 0.0, 0.0);
  REQUIRE(ref.v.z() > 0.0);
  const double points[][2] = {
      {0.0, 0.0}, {1e-3, 0.0}, {0.6e-3, 0.3e-3}, {1e-3, 1e-3}, {2e-3, 2e-3}};
  for (const auto& pt : points) {
    const Bounce b = bounce(true, pt[0], pt[1]);
    INFO("impact at (" << pt[0] << ", " << pt[1] << "): v_z " << b.v.z() << " plane " << ref.v.z()
                       << "; F_max " << b.force_max << " plane " << ref.force_max);
    CHECK(std::abs(b.v.z() - ref.v.z()) <= 1e-6 * std::abs(ref.v.z()));
    CHECK(std::abs(b.force_max - ref.force_max) <= 1e-6 * ref.force_max);
    CHECK(b.v.head<2>().norm() < 1e-9);
    CHECK(b.w.norm() < 1e-6);
  }
}

TEST_CASE("dem: mesh forces are distributed to vertices and balance the particle", "[dem][mesh]") {
  System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
  sys.set_gravity({0, 0, -9.81});
  Eigen::MatrixX3d v(3, 3);
  v << -5e-3, -5e-3, 0, 5e-3, -5e-3, 0, 0, 5e-3, 0;
  TriangleMesh::Triangles t(1, 3);
  t << 0, 1, 2;
  const int mesh = sys.add_mesh(v, t, 0);
  sys.add_particle({0.0, 0.0, R * 0.999}, R, 0);
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(20000, dt);  // settle at rest on the triangle
  const double weight = test::sphere_mass(R, RHO) * 9.81;
  const Eigen::MatrixX3d& fv = sys.vertex_forces(mesh);
  CHECK(sys.mesh_force(mesh).z() == Approx(-weight).epsilon(1e-3));
  CHECK(fv.col(2).sum() == Approx(-weight).epsilon(1e-3));
  CHECK(sys.triangle_forces(mesh)(0, 2) == Approx(-weight).epsilon(1e-3));
  // lever rule: the contact point (0, 0) has barycentric weights (0.25, 0.25, 0.5)
  CHECK(fv(2, 2) == Approx(-0.5 * weight).epsilon(1e-3));
  CHECK(fv(0, 2) == Approx(-0.25 * weight).epsilon(1e-3));
}

TEST_CASE("dem: a mesh moved by the caller pushes a particle like a moving plane", "[dem][mesh]") {
  // A resting sphere hit by a wall moving up at 0.2 m/s: the relative velocity enters the
  // contact, so the sphere leaves at (1 + e) 0.2 m/s whether the wall is a plane or a mesh whose
  // vertices the caller displaces every step (velocities from the motion).
  const double u = 0.2, e = 0.5;
  auto run = [&](bool mesh) {
    System sys = test::single_material(E, NU, RHO, e, 0.0);
    sys.add_particle({0.0, 0.0, R + 2e-6}, R, 0);
    Eigen::MatrixX3d v;
    TriangleMesh::Triangles t;
    triangulated_plane(4.0 * R, 2, v, t);
    int id = -1;
    if (mesh)
      id = sys.add_mesh(v, t, 0);
    else
      sys.add_plane({0, 0, 0}, {0, 0, 1}, 0, {0, 0, u});
    const double dt = 0.1 * sys.rayleigh_time_step();
    for (int s = 1; s <= 3000; ++s) {
      if (mesh) {
        Eigen::MatrixX3d x = v;
        x.col(2).array() += u * dt * s;
        sys.set_vertex_positions(id, x);
      }
      sys.step(dt);
      if (s > 100 && sys.particles().velocity[0].z() > 1.2 * u) break;  // left the wall
    }
    return sys.particles().velocity[0].z();
  };
  const double vp = run(false), vm = run(true);
  INFO("plane " << vp << " mesh " << vm << " theory " << (1 + e) * u);
  CHECK(vp == Approx((1 + e) * u).epsilon(0.02));
  CHECK(vm == Approx(vp).epsilon(1e-6));
}
