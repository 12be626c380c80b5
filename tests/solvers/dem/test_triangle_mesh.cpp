// Sphere-triangle contacts: same rebound as on a plane wherever the sphere hits a triangulated
// plane (face, shared edge, shared vertex), force distribution to vertices, moving meshes.

#include "dem_test_helpers.hpp"

#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

#include <numbers>
#include <sstream>

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

// Drops a sphere vertically (with friction and damping on) at (x, y, z0) onto a plane or a
// mesh. The mesh is the triangulated plane folded along x = 0 to z = fold |x| (fold 0: flat;
// fold 1: a 90-degree V-groove; fold -1: a 90-degree ridge).
Bounce bounce(bool on_mesh, double x, double y, int cells = 4, double fold = 0.0,
              double z0 = R + 1e-5) {
  System sys = test::single_material(E, NU, RHO, 0.5, 0.4);
  sys.add_particle({x, y, z0}, R, 0, {0.0, 0.0, -0.5});
  int mesh = -1, wall = -1;
  if (on_mesh) {
    Eigen::MatrixX3d v;
    TriangleMesh::Triangles t;
    triangulated_plane(4.0 * R, cells, v, t);
    v.col(2) = fold * v.col(0).cwiseAbs();
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

// The same drop into a V-groove of two rigid planes z = |x| (normals (-+1, 0, 1)/sqrt 2).
Bounce bounce_in_planes_groove(double z0) {
  System sys = test::single_material(E, NU, RHO, 0.5, 0.4);
  sys.add_particle({0.0, 0.0, z0}, R, 0, {0.0, 0.0, -0.5});
  const double c = std::sqrt(0.5);
  const int w1 = sys.add_plane({0, 0, 0}, {-c, 0, c}, 0);
  const int w2 = sys.add_plane({0, 0, 0}, {c, 0, c}, 0);
  const double dt = 0.1 * sys.rayleigh_time_step();
  double fmax = 0.0;
  for (int s = 0; s < 4000; ++s) {
    sys.step(dt);
    fmax = std::max(fmax, (sys.wall_force(w1) + sys.wall_force(w2)).norm());
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

TEST_CASE("dem: a fine mesh with many triangles under the contact still acts like a plane",
          "[dem][mesh][slow]") {
  // h = 0.05 mm: about 90 triangles intersect the sphere at the largest overlap (18 um, contact
  // circle of 0.19 mm radius); only the face under the centre carries the contact.
  const Bounce ref = bounce(false, 0.0, 0.0);
  for (const auto& pt : {std::pair{0.0, 0.0}, std::pair{0.0123e-3, 0.0371e-3}}) {
    const Bounce b = bounce(true, pt.first, pt.second, 160);
    INFO("impact at (" << pt.first << ", " << pt.second << "): v_z " << b.v.z() << " plane "
                       << ref.v.z() << "; F_max " << b.force_max << " plane " << ref.force_max);
    CHECK(std::abs(b.v.z() - ref.v.z()) <= 1e-6 * std::abs(ref.v.z()));
    CHECK(std::abs(b.force_max - ref.force_max) <= 1e-6 * ref.force_max);
  }
}

TEST_CASE("dem: a fine folded mesh acts like its planes: V-groove (two faces), ridge (one edge)",
          "[dem][mesh][slow]") {
  // h = 0.05 mm. In the groove the sphere touches the two faces whose planes it overlaps; the
  // edges and vertices of the triangles around them, also within reach, are not contacts. On
  // the ridge it touches the ridge edge only (overlap and normal of a horizontal plane).
  const double z_groove = std::sqrt(2.0) * (R + 1e-5);
  const Bounce groove_ref = bounce_in_planes_groove(z_groove);
  REQUIRE(groove_ref.v.z() > 0.0);
  const Bounce groove = bounce(true, 0.0, 0.0123e-3, 160, 1.0, z_groove);
  INFO("groove: v_z " << groove.v.z() << " planes " << groove_ref.v.z() << "; F_max "
                      << groove.force_max << " planes " << groove_ref.force_max);
  CHECK(std::abs(groove.v.z() - groove_ref.v.z()) <= 1e-6 * std::abs(groove_ref.v.z()));
  CHECK(std::abs(groove.force_max - groove_ref.force_max) <= 1e-6 * groove_ref.force_max);

  const Bounce ref = bounce(false, 0.0, 0.0);
  const Bounce ridge = bounce(true, 0.0, 0.0123e-3, 160, -1.0);
  INFO("ridge: v_z " << ridge.v.z() << " plane " << ref.v.z() << "; F_max " << ridge.force_max
                     << " plane " << ref.force_max);
  CHECK(std::abs(ridge.v.z() - ref.v.z()) <= 1e-6 * std::abs(ref.v.z()));
  CHECK(std::abs(ridge.force_max - ref.force_max) <= 1e-6 * ref.force_max);
  CHECK(ridge.v.head<2>().norm() < 1e-9);
}

TEST_CASE("dem: rolling down an incline across many triangles equals rolling on a plane",
          "[dem][mesh][slow]") {
  // Gravity tilted by 20 degrees over a flat floor; friction 0.5 > 2/7 tan(20 deg), so the
  // sphere rolls without slipping, a = 5/7 g sin(theta). On a mesh of h = 0.05 mm it crosses
  // about 10 triangles in 0.02 s: the static friction (tangential history) must pass from
  // triangle to triangle, or the sphere slips at each crossing.
  const double theta = 20.0 * std::numbers::pi / 180.0, g = 9.81, duration = 0.02;
  const auto roll = [&](bool on_mesh, double& time) {
    System sys = test::single_material(E, NU, RHO, 0.5, 0.5);
    sys.set_gravity({g * std::sin(theta), 0.0, -g * std::cos(theta)});
    sys.add_particle({-3e-3, 0.0123e-3, R - 1e-7}, R, 0, {0.0, 0.0, 0.0});
    if (on_mesh) {
      Eigen::MatrixX3d v;
      TriangleMesh::Triangles t;
      triangulated_plane(4.0 * R, 160, v, t);
      sys.add_mesh(v, t, 0);
    } else {
      sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
    }
    const double dt = 0.1 * sys.rayleigh_time_step();
    time = 0.0;
    for (; time < duration; time += dt) sys.step(dt);
    return std::pair{sys.particles().velocity[0], sys.particles().angular_velocity[0]};
  };
  double t_plane = 0.0, t_mesh = 0.0;
  const auto [v_plane, w_plane] = roll(false, t_plane);
  const auto [v_mesh, w_mesh] = roll(true, t_mesh);
  const double v_rolling = 5.0 / 7.0 * g * std::sin(theta) * t_plane;
  INFO("v_x plane " << v_plane.x() << ", mesh " << v_mesh.x() << ", rolling " << v_rolling
                    << "; w_y R mesh " << w_mesh.y() * R);
  REQUIRE(t_mesh == t_plane);
  // the plane itself: rolling without slip (the first contact bounce costs a little)
  CHECK(std::abs(v_plane.x() - v_rolling) <= 1e-3 * v_rolling);
  CHECK(std::abs(w_plane.y() * R - v_plane.x()) <= 1e-3 * v_rolling);
  CHECK(std::abs(v_mesh.x() - v_plane.x()) <= 1e-6 * v_rolling);
  CHECK(std::abs(w_mesh.y() - w_plane.y()) <= 1e-6 * std::abs(w_plane.y()));
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

TEST_CASE("dem: a large moving mesh (parallel vertex loops) pushes like a plane on 1 and 2 threads",
          "[dem][mesh][threads]") {
  // As above with a mesh of 131 x 131 = 17,161 vertices (34,322 triangles): enough for the
  // step's vertex loops (velocities from the motion, the copy of the positions, the rebuild test,
  // the force shares) to run on the threads. The vertices' velocities are the motion's, u.
  const double u = 0.2, e = 0.5;
  const int before = max_threads();
  double first = 0.0;
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    System sys = test::single_material(E, NU, RHO, e, 0.0);
    sys.add_particle({0.0, 0.0, R + 2e-6}, R, 0);
    Eigen::MatrixX3d v;
    TriangleMesh::Triangles t;
    triangulated_plane(4.0 * R, 130, v, t);
    REQUIRE(v.rows() >= parallel_pass_min);
    const int id = sys.add_mesh(v, t, 0);
    const double dt = 0.1 * sys.rayleigh_time_step();
    const long builds0 = sys.neighbor_list().build_count();
    for (int s = 1; s <= 3000; ++s) {
      Eigen::MatrixX3d x = v;
      x.col(2).array() += u * dt * s;
      sys.set_vertex_positions(id, x);
      sys.step(dt);
      if (s > 100 && sys.particles().velocity[0].z() > 1.2 * u) break;  // left the wall
    }
    INFO(threads << " threads");
    double vz_min = 1e300, vz_max = -1e300;
    for (const Eigen::Vector3d& w : sys.mesh(id).velocities())
      vz_min = std::min(vz_min, w.z()), vz_max = std::max(vz_max, w.z());
    CHECK(vz_min == Approx(u).epsilon(1e-6));
    CHECK(vz_max == Approx(u).epsilon(1e-6));
    CHECK(sys.neighbor_list().build_count() > builds0 + 1);  // the mesh's motion rebuilt the lists
    const double vp = sys.particles().velocity[0].z();
    CHECK(vp == Approx((1 + e) * u).epsilon(0.02));
    if (threads == 1)
      first = vp;
    else
      CHECK(vp == first);  // the same bits on any number of threads
  }
  set_num_threads(before);
}

TEST_CASE("dem: mesh contact rows exist only for particles near a mesh and follow them",
          "[dem][mesh][lifecycle]") {
  // A layer of 5 x 5 spheres 1 um into a triangulated plane at z = 0 and a layer 12 R above it,
  // 3 R apart (no pair contacts): only the first layer is within R + skin of the mesh, and each
  // of its spheres touches the plane once (one face or edge: coplanar features count once).
  System sys;
  const int m = sys.add_material({E, NU, RHO});
  sys.add_interaction(m, m, {0.3, 0.5, 0.0});
  sys.set_skin(0.1 * R);
  for (const double z : {R - 1e-6, 12 * R})
    for (int a = 0; a < 5; ++a)
      for (int b = 0; b < 5; ++b)
        sys.add_particle({(3 * a - 6 + 0.1) * R, (3 * b - 6 + 0.2) * R, z}, R, m);
  {  // a state written before the first step (no lists, no rows yet) reads back
    std::stringstream state;
    sys.write_state(state);
    CHECK_NOTHROW(sys.read_state(state));
  }
  const double dt = 0.1 * sys.rayleigh_time_step();
  sys.step(dt);
  // without a mesh: no mesh rows and no per-particle mesh array
  CHECK(sys.mesh_contacts().row_count() == 0);
  for (int k = 0; k < sys.store().array_count(); ++k)
    CHECK(sys.store().array_name(k).find("mesh") == std::string::npos);
  Eigen::MatrixX3d v;
  TriangleMesh::Triangles t;
  triangulated_plane(10 * R, 8, v, t);
  sys.add_mesh(v, t, m);
  sys.step(dt);
  CHECK(sys.mesh_contacts().row_count() == 25);
  CHECK(sys.mesh_contacts().contact_count() == 25);
  CHECK(sys.mesh_force(0).z() < 0.0);  // the spheres push the plane down
  // every other sphere of the first layer removed: its rows and contacts go with it, the others'
  // follow their particles (also through a renumbering)
  std::vector<char> remove(sys.particle_count(), 0);
  for (std::size_t i = 0; i < 25; i += 2) remove[i] = 1;
  sys.remove_particles(remove);
  CHECK(sys.mesh_contacts().row_count() == 12);
  CHECK(sys.mesh_contacts().contact_count() == 12);
  std::vector<int> order(sys.particle_count());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(order.size() - 1 - k);
  sys.renumber_particles(order);
  CHECK(sys.mesh_contacts().contact_count() == 12);
  sys.step(dt);
  CHECK(sys.mesh_contacts().row_count() == 12);
  CHECK(sys.mesh_contacts().contact_count() == 12);
  for (std::size_t i = 0; i < sys.particle_count(); ++i)  // the first layer is now at the end
    CHECK((sys.particles().position[i].z() < 2 * R) == (i >= 25));
}

TEST_CASE("dem: a particle falls through where mesh triangles are taken out, beside one held",
          "[dem][mesh]") {
  // The square [-4R, 4R]^2 in 2 x 2 cells of 4R; particle A rests over the middle of cell
  // (0, 0), particle B over cell (1, 1), under gravity. With cell (0, 0)'s two triangles taken
  // out, A falls freely (z = R - g t^2 / 2) and B stays held (overlap << R).
  System sys = test::single_material(E, NU, RHO, 0.5, 0.4);
  const double g = 9.81;
  sys.set_gravity({0, 0, -g});
  sys.add_particle({-2 * R, -2 * R, R}, R, 0, {0, 0, 0});
  sys.add_particle({2 * R, 2 * R, R}, R, 0, {0, 0, 0});
  Eigen::MatrixX3d v;
  TriangleMesh::Triangles t;
  triangulated_plane(4.0 * R, 2, v, t);
  const int mesh = sys.add_mesh(v, t, 0);
  CHECK(sys.mesh(mesh).inactive_triangle_count() == 0);
  sys.set_triangle_active(mesh, 0, false);  // cell (0, 0): triangles 0 and 1
  sys.set_triangle_active(mesh, 1, false);
  sys.set_triangle_active(mesh, 1, false);  // twice: counted once
  CHECK(sys.mesh(mesh).inactive_triangle_count() == 2);
  CHECK_FALSE(sys.mesh(mesh).triangle_active(0));
  CHECK(sys.mesh(mesh).triangle_active(2));
  const double dt = 0.2 * sys.rayleigh_time_step();
  const int steps = static_cast<int>(0.03 / dt);
  for (int s = 0; s < steps; ++s) sys.step(dt);
  const double time = steps * dt;
  const auto& p = sys.particles();
  const int a = p.position[0].x() < 0.0 ? 0 : 1;  // A: over cell (0, 0)
  CHECK(p.position[a].z() == Approx(R - 0.5 * g * time * time).epsilon(1e-6));
  CHECK(p.position[1 - a].z() == Approx(R).epsilon(1e-3));
  const double weight = test::sphere_mass(R, RHO) * g;
  CHECK(sys.mesh_force(mesh).z() == Approx(-weight).epsilon(1e-2));
  // The triangle forces: B rests on the diagonal (vertices 4 and 8) of cell (1, 1), half its
  // weight on each by the lever rule. The middle vertex 4 has eight triangles, six of them
  // active: each active one gets W/2 / 6 from it, the two removed ones nothing (their surface is
  // gone); the corner vertex 8 gives W/2 / 2 to each triangle of cell (1, 1). Triangles: cell
  // (0, 0) 0, 1; (1, 0) 2, 3; (0, 1) 4, 5; (1, 1) 6, 7.
  const Eigen::MatrixX3d& ft = sys.triangle_forces(mesh);
  const double f = sys.mesh_force(mesh).z();  // (B's contact force: W while it rests)
  CHECK(ft.row(0).norm() == 0.0);
  CHECK(ft.row(1).norm() == 0.0);
  for (int k = 2; k < 6; ++k) CHECK(ft(k, 2) == Approx(f / 12.0).epsilon(1e-9));
  for (int k = 6; k < 8; ++k) CHECK(ft(k, 2) == Approx(f / 3.0).epsilon(1e-9));
  CHECK((ft.colwise().sum() - sys.vertex_forces(mesh).colwise().sum()).norm() <=
        1e-12 * weight);
  CHECK_THROWS_AS(sys.set_triangle_active(mesh, 8, false), Error);
}

TEST_CASE("dem: the rim of a hole in a mesh acts by its edge", "[dem][mesh]") {
  // Over cell (0, 0) of the 2 x 2 square, 0.5 R from its edge x = 0 with cell (1, 0): the face
  // below is the mesh's nearest feature; once cell (0, 0) is taken out, the edge x = 0 of cell
  // (1, 0) is (the rim of the hole), and no feature of the removed triangles is.
  Eigen::MatrixX3d v;
  TriangleMesh::Triangles t;
  triangulated_plane(4.0 * R, 2, v, t);
  TriangleMesh m(v, t, 0);
  const Eigen::Vector3d p(-0.5 * R, -2.0 * R, 0.5 * R);
  // the features that are local closest points within reach 2 R of p: (triangle, feature)
  const auto features = [&] {
    std::vector<std::pair<int, int>> out;
    for (int k = 0; k < m.triangle_count(); ++k) {
      if (!m.triangle_active(k)) continue;
      const auto cp = m.closest_point(k, p);
      if ((cp.point - p).norm() < 2 * R && m.feature_is_local_closest(k, cp, p))
        out.emplace_back(k, static_cast<int>(cp.feature));
    }
    return out;
  };
  const auto before = features();
  REQUIRE(before.size() == 1);
  CHECK(before[0].second == TriangleClosestPoint::face);
  CHECK(before[0].first < 2);  // a triangle of cell (0, 0)
  m.set_triangle_active(0, false);
  m.set_triangle_active(1, false);
  const auto after = features();
  REQUIRE(after.size() >= 1);
  for (const auto& [k, feature] : after) {
    CHECK(k >= 2);
    CHECK(feature == TriangleClosestPoint::edge);
    const auto cp = m.closest_point(k, p);
    CHECK(cp.point.x() == Approx(0.0).margin(1e-15));
  }
  m.set_triangle_active(0, true);
  m.set_triangle_active(1, true);
  CHECK(features() == before);
}
