// Crushable granules (seed 001, eq. 2): the breaking force, the comminution limit, conservation
// at breakage, the Weibull strength scatter, thread independence and repeatable windows.

#include "dem_test_helpers.hpp"

#include "partita/dem/breakage.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/grading.hpp"
#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

using namespace partita::dem;

namespace {

constexpr double E = 1.0e9, NU = 0.3, RHO = 2500.0;  // granule
constexpr double E_P = 200.0e9, NU_P = 0.3;          // platens

BreakageParameters parameters(double m, bool scatter = false) {
  BreakageParameters b;
  b.limit_strength = 30.0e6;
  b.reference_size = 2.0e-3;
  b.weibull_modulus = m;
  b.scatter = scatter;
  b.comminution_limit = 0.1e-3;
  return b;
}

Breakage& breakage_of(System& sys) {
  return static_cast<Breakage&>(sys.hook(0));
}
const Breakage& breakage_of(const System& sys) {
  return static_cast<const Breakage&>(sys.hook(0));
}

// A granule (material 0) of diameter d resting on a floor z = 0 of platen steel (material 1).
void granule_on_floor(System& sys, double d) {
  const int g = sys.add_material({E, NU, RHO});
  const int s = sys.add_material({E_P, NU_P, 7850.0});
  sys.add_interaction(g, g, {0.3, 0.5, 0.0});
  sys.add_interaction(g, s, {0.3, 0.5, 0.0});
  sys.add_particle({0, 0, 0.5 * d}, 0.5 * d, g);
  sys.add_plane({0, 0, 0}, {0, 0, 1}, s);
}

// A granule of diameter d resting on a floor z = 0, a top platen touching it and moving down at
// speed u; no gravity.
struct Platens {
  System sys;
  int top = -1;
  double u = 0.0;
  Platens(double d, const BreakageParameters& b, double speed) : u(speed) {
    granule_on_floor(sys, d);
    top = sys.add_plane({0, 0, d}, {0, 0, -1}, 1, {0, 0, -speed});
    sys.add_hook(std::make_unique<Breakage>(b));
  }
};

// Eq. 2 of seed 001, written out: F = [sigma pi (3 r'/(4 E'))^(2/3)]^3 with 1/E' = (1-nu1^2)/E1 +
// (1-nu2^2)/E2, r' = r against a plane, sigma = sigma_lim,0 (d/d0)^(-3/m).
double eq2_force(double d, const BreakageParameters& b) {
  const double e_eff = 1.0 / ((1.0 - NU * NU) / E + (1.0 - NU_P * NU_P) / E_P);
  const double sigma = b.limit_strength * std::pow(d / b.reference_size, -3.0 / b.weibull_modulus);
  return std::pow(sigma * std::numbers::pi * std::pow(3.0 * 0.5 * d / (4.0 * e_eff), 2.0 / 3.0), 3);
}

struct Motion {
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), l = Eigen::Vector3d::Zero();  // about `centre`
  double ke = 0.0, mass = 0.0;
  Motion(const System& s, const Eigen::Vector3d& centre) {
    const Particles& q = s.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      p += q.mass[i] * q.velocity[i];
      l += q.mass[i] * (q.position[i] - centre).cross(q.velocity[i]) +
           q.inertia[i] * q.angular_velocity[i];
      ke += 0.5 * q.mass[i] * q.velocity[i].squaredNorm() +
            0.5 * q.inertia[i] * q.angular_velocity[i].squaredNorm();
      mass += q.mass[i];
    }
  }
};

}  // namespace

TEST_CASE("dem: a granule between two platens breaks at the force of eq. 2", "[dem][breakage]") {
  for (double m : {3.0, 10.0})
    for (double d : {2.0e-3, 4.0e-3}) {
      const BreakageParameters b = parameters(m);
      Platens t(d, b, 0.005);
      const double dt = 0.2 * t.sys.rayleigh_time_step();
      const double f_c = eq2_force(d, b);
      double f = 0.0;
      long steps = 0;
      for (; steps < 2'000'000 && breakage_of(t.sys).counters().events == 0; ++steps) {
        t.sys.step(dt);
        f = t.sys.wall_force(t.top).norm();  // the top platen's force in this step
      }
      INFO("m " << m << ", d " << d << ": broke after " << steps << " steps at F = " << f
                << " N; eq. 2: " << f_c << " N");
      REQUIRE(breakage_of(t.sys).counters().events == 1);
      CHECK(f == Approx(f_c).epsilon(0.01));
      CHECK(t.sys.particle_count() == 14);  // apollonian-14 by default
    }
}

TEST_CASE("dem: below the comminution limit a granule never breaks", "[dem][breakage]") {
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3;
  b.comminution_limit = 2.5e-3;
  Platens t(d, b, 0.01);
  const double dt = 0.2 * t.sys.rayleigh_time_step();
  const double f_c = eq2_force(d, b);
  double f = 0.0;
  for (long s = 0; s < 2'000'000 && f < 3.0 * f_c; ++s) {
    t.sys.step(dt);
    f = t.sys.wall_force(t.top).norm();
  }
  INFO("F " << f << " N, eq. 2 " << f_c << " N");
  CHECK(f >= 3.0 * f_c);
  CHECK(breakage_of(t.sys).counters().events == 0);
  CHECK(t.sys.particle_count() == 1);
}

TEST_CASE("dem: below the comminution limit a granule squeezed by a mesh turns to powder at the "
          "force of eq. 2", "[dem][breakage][energy]") {
  // The case of a fragment caught between a rigid bow (a moving mesh) and a plate (the floor):
  // unbreakable, it is squeezed until the mesh passes it; with powder on it leaves the system
  // when its contacts reach its strength (the same criterion as above the limit), its mass and
  // its energy counted, and the energy balance closes across the removal.
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3, speed = 0.005;
  b.comminution_limit = 2.5e-3;
  b.powder = true;
  System sys;
  granule_on_floor(sys, d);
  const int s = 1;  // the platens' steel
  Eigen::MatrixX3d x(4, 3);  // a square of side 4 d at the granule's top
  x << -2 * d, -2 * d, d, 2 * d, -2 * d, d, 2 * d, 2 * d, d, -2 * d, 2 * d, d;
  TriangleMesh::Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  const int mesh = sys.add_mesh(x, t, s);
  sys.add_hook(std::make_unique<Breakage>(b));
  sys.set_energy_tracking(true);
  const double mass = test::sphere_mass(0.5 * d, RHO);
  const double dt = 0.2 * sys.rayleigh_time_step();
  const Eigen::MatrixX3d x0 = x;
  double f = 0.0;
  long steps = 0;
  for (; steps < 2'000'000 && breakage_of(sys).counters().powder_events == 0; ++steps) {
    x.col(2) = x0.col(2).array() - speed * dt * static_cast<double>(steps + 1);
    sys.set_vertex_positions(mesh, x);
    sys.step(dt);
    f = sys.mesh_force(mesh).norm();
  }
  const BreakageCounters& c = breakage_of(sys).counters();
  // the energy of the two Hertz contacts (floor and mesh, same materials) carrying F:
  // 2 x 2/5 F delta, delta = (3 F / (4 E' sqrt(r)))^(2/3)
  const double e_eff = 1.0 / ((1.0 - NU * NU) / E + (1.0 - NU_P * NU_P) / E_P);
  const double delta = std::pow(3.0 * f / (4.0 * e_eff * std::sqrt(0.5 * d)), 2.0 / 3.0);
  const double stored = 2.0 * 0.4 * f * delta;
  const System::Energies& e = sys.energies();
  INFO("powder after " << steps << " steps at F = " << f << " N; eq. 2: " << eq2_force(d, b)
                       << " N; powder energy " << c.powder_energy << " J, 2 x 2/5 F delta "
                       << stored << " J, breakage " << e.breakage << " J, mesh work "
                       << e.mesh_work[0] << " J, balance error " << sys.energy_balance_error());
  REQUIRE(c.powder_events == 1);
  CHECK(f == Approx(eq2_force(d, b)).epsilon(0.01));
  CHECK(sys.particle_count() == 0);
  CHECK(c.events == 0);
  CHECK(c.fragments == 0);
  CHECK(c.powder_mass == Approx(mass).epsilon(1e-12));
  CHECK(c.powder_energy == Approx(stored).epsilon(0.02));
  CHECK(c.energy_released == c.powder_energy);
  // the system's own books: the mechanical energy that left with the particle
  CHECK(e.breakage == Approx(c.powder_energy).epsilon(0.02));
  CHECK(std::abs(sys.energy_balance_error()) < 2e-3);
  // the same squeeze without powder: the granule stays and the mesh presses it beyond eq. 2
  b.powder = false;
  System keep;
  granule_on_floor(keep, d);
  const int m2 = keep.add_mesh(x0, t, s);
  keep.add_hook(std::make_unique<Breakage>(b));
  for (long k = 0; k < 2 * steps; ++k) {
    x.col(2) = x0.col(2).array() - speed * dt * static_cast<double>(k + 1);
    keep.set_vertex_positions(m2, x);
    keep.step(dt);
  }
  CHECK(keep.particle_count() == 1);
  CHECK(keep.mesh_force(m2).norm() > 2.0 * eq2_force(d, b));
  CHECK(breakage_of(keep).counters().powder_events == 0);
}

TEST_CASE("dem: below the comminution limit a granule squeezed by a mesh yields at the pressure "
          "of eq. 2", "[dem][breakage][energy]") {
  // The fragment of the test above, with below_limit yield: the mesh contact holds its mean
  // pressure at the granule's strength, so its force stays at eq. 2's while the mesh goes on
  // down by a quarter of a diameter; the overlap beyond becomes permanent and its work is dissipated
  // (booked with the damping); the granule keeps its mass and stores only the elastic energy at
  // yield, where the unbreakable one stores the Hertz energy of the whole squeeze.
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3, speed = 0.005;
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double e_eff = 1.0 / ((1.0 - NU * NU) / E + (1.0 - NU_P * NU_P) / E_P);
  const double f_y = eq2_force(d, b);
  // the overlap at which a Hertz contact of R = d/2 carries f_y
  const double delta_y = std::pow(3.0 * f_y / (4.0 * e_eff * std::sqrt(0.5 * d)), 2.0 / 3.0);
  Eigen::MatrixX3d x(4, 3);  // a square of side 4 d at the granule's top
  x << -2 * d, -2 * d, d, 2 * d, -2 * d, d, 2 * d, 2 * d, d, -2 * d, 2 * d, d;
  TriangleMesh::Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  const Eigen::MatrixX3d x0 = x;
  struct Squeeze {
    double max_force = 0.0, force = 0.0, elastic = 0.0, damping = 0.0, balance = 0.0;
    std::size_t particles = 0;
    double mass = 0.0;
  };
  const auto squeeze = [&](bool yield) {
    b.yield = yield;
    System sys;
    granule_on_floor(sys, d);
    const int mesh = sys.add_mesh(x0, t, 1);
    sys.add_hook(std::make_unique<Breakage>(b));
    sys.set_energy_tracking(true);
    const double dt = 0.2 * sys.rayleigh_time_step();
    // down by the two elastic overlaps (the granule's top touches the mesh at the start) plus a
    // quarter of a diameter (the mesh stays above the granule's centre)
    const auto steps = static_cast<long>((0.25 * d + 2.0 * delta_y) / (speed * dt));
    Squeeze r;
    Eigen::MatrixX3d y = x0;
    for (long k = 0; k < steps; ++k) {
      y.col(2) = x0.col(2).array() - speed * dt * static_cast<double>(k + 1);
      sys.set_vertex_positions(mesh, y);
      sys.step(dt);
      r.max_force = std::max(r.max_force, sys.mesh_force(mesh).norm());
    }
    r.force = sys.mesh_force(mesh).norm();
    r.elastic = sys.elastic_energy();
    r.damping = sys.energies().damping;
    r.balance = sys.energy_balance_error();
    r.particles = sys.particle_count();
    r.mass = sys.particles().mass[0];
    return r;
  };
  const Squeeze yielding = squeeze(true), elastic = squeeze(false);
  INFO("yield: max force " << yielding.max_force << " N, eq. 2 " << f_y << " N; elastic energy "
                           << yielding.elastic << " J (unbreakable " << elastic.elastic
                           << " J), damping " << yielding.damping << " J, balance error "
                           << yielding.balance);
  // the force holds at eq. 2's (the floor, a plane, stays elastic and carries the same force)
  CHECK(yielding.max_force == Approx(f_y).epsilon(0.01));
  CHECK(yielding.force == Approx(f_y).epsilon(0.01));
  CHECK(elastic.force > 10.0 * f_y);
  // the granule stays whole, with its mass
  CHECK(yielding.particles == 1);
  CHECK(yielding.mass == Approx(test::sphere_mass(0.5 * d, RHO)).epsilon(1e-12));
  // stored: the two contacts at yield, 2 x 2/5 f_y delta_y; dissipated: f_y times the permanent
  // overlap, the mesh's travel beyond the elastic overlaps (0.25 d)
  CHECK(yielding.elastic == Approx(2.0 * 0.4 * f_y * delta_y).epsilon(0.02));
  CHECK(yielding.damping == Approx(f_y * 0.25 * d).epsilon(0.02));
  CHECK(std::abs(yielding.balance) < 2e-3);
  CHECK(elastic.elastic > 50.0 * yielding.elastic);
}

TEST_CASE("dem: a yielding granule pressed into a thick steel block is flattened to its centre, "
          "then held elastically, then crushed to powder at 1.5 times its strength, never "
          "pushed into the block", "[dem][breakage][energy]") {
  // A granule below the comminution limit (below_limit yield) on the top face of a closed
  // one-sided block 4 d thick, pressed by a plane (elastic, as planes are) coming down slowly.
  // The block's contact yields at f_y until its permanent overlap is the granule's radius (the
  // centre on the face: the plane has come down by r plus the two contacts' elastic overlaps at
  // f_y), then both contacts are elastic (Hertz, R = r) and the force rises; at 1.5^3 f_y (the
  // mean contact pressure 1.5 sigma) the granule is crushed to powder, its mass counted. Its
  // centre is never deeper behind the face than the Hertz overlap of that force. (A permanent
  // overlap without bound would let it sink at f_y through the face; deeper than r no face
  // touches it.)
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3, r = 0.5 * d, speed = 0.005;
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double e_eff = 1.0 / ((1.0 - NU * NU) / E + (1.0 - NU_P * NU_P) / E_P);
  const double f_y = eq2_force(d, b), f_crush = 1.5 * 1.5 * 1.5 * f_y;
  const auto hertz_overlap = [&](double f) {  // R = r
    return std::pow(3.0 * f / (4.0 * e_eff * std::sqrt(r)), 2.0 / 3.0);
  };
  const double delta_y = hertz_overlap(f_y), delta_c = hertz_overlap(f_crush);
  const double mass = test::sphere_mass(r, RHO);
  System sys;
  const int g = sys.add_material({E, NU, RHO});
  const int s = sys.add_material({E_P, NU_P, 7850.0});
  sys.add_interaction(g, g, {0.3, 0.5, 0.0});
  sys.add_interaction(g, s, {0.3, 0.5, 0.0});
  sys.add_particle({0.1 * d, 0.2 * d, r}, r, g);  // touching the top face z = 0
  // the block [-4d, 4d]^2 x [-4d, 0]: 8 corners, 12 triangles counter-clockwise from outside
  const double a = 4.0 * d;
  Eigen::MatrixX3d x(8, 3);
  for (int c = 0; c < 8; ++c)
    x.row(c) << ((c & 1) ? a : -a), ((c & 2) ? a : -a), ((c & 4) ? 0.0 : -a);
  const int quads[6][4] = {{4, 5, 7, 6}, {0, 2, 3, 1}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  TriangleMesh::Triangles t(12, 3);
  for (int f = 0; f < 6; ++f) {
    t.row(2 * f) << quads[f][0], quads[f][1], quads[f][2];
    t.row(2 * f + 1) << quads[f][0], quads[f][2], quads[f][3];
  }
  const int block = sys.add_mesh(x, t, s);
  sys.set_mesh_one_sided(block, true);
  for (int k = 0; k < 12; ++k) {  // (the orientation: every normal points away from the centre)
    const Eigen::Vector3d c = (x.row(t(k, 0)) + x.row(t(k, 1)) + x.row(t(k, 2))).transpose() / 3.0;
    REQUIRE(sys.mesh(block).normal(k).dot(c - Eigen::Vector3d(0, 0, -0.5 * a)) > 0.0);
  }
  sys.add_plane({0, 0, d}, {0, 0, -1}, s, {0, 0, -speed});  // touching the granule's top
  sys.add_hook(std::make_unique<Breakage>(b));
  sys.set_energy_tracking(true);
  const double dt = 0.2 * sys.rayleigh_time_step();
  // the plane's travel to the crushing: r + the two elastic overlaps at f_y (yield) + twice
  // the Hertz overlap of f_crush beyond them; 10 % more
  const double travel = r + 2.0 * delta_c;
  const auto steps = static_cast<long>(1.1 * travel / (speed * dt));
  double z_min = 1.0, f_max = 0.0, f_at_r = 0.0;
  long crushed_at = -1;
  for (long k = 0; k < steps && crushed_at < 0; ++k) {
    sys.step(dt);
    if (sys.particle_count() == 0) {
      crushed_at = k;
      break;
    }
    const double z = sys.particles().position[0].z();
    z_min = std::min(z_min, z);
    const double f = -sys.mesh_force(block).z();
    f_max = std::max(f_max, f);
    // the plane's travel at r + 2 delta_y less a tenth of r: still yielding at f_y
    if (std::abs(speed * dt * static_cast<double>(k + 1) - (0.9 * r + 2.0 * delta_y)) < 0.5 * speed * dt)
      f_at_r = f;
  }
  const BreakageCounters& n = breakage_of(sys).counters();
  INFO("f_y " << f_y << " N, crushing force " << f_crush << " N; the block's force at 0.9 r "
              << f_at_r << " N, largest " << f_max << " N; lowest centre " << z_min
              << " m (Hertz overlap of the crushing force " << delta_c << " m); crushed after "
              << crushed_at << " of " << steps << " steps; powder " << n.powder_events << ", "
              << n.powder_mass << " kg; yield and damping work " << sys.energies().damping
              << " J (f_y r " << f_y * r << " J); balance error " << sys.energy_balance_error());
  // yielding at f_y while it flattens
  CHECK(f_at_r == Approx(f_y).epsilon(0.01));
  // crushed once the force reached 1.5^3 f_y, its mass counted, never deep in the block
  REQUIRE(crushed_at > 0);
  CHECK(f_max == Approx(f_crush).epsilon(0.01));
  CHECK(n.powder_events == 1);
  CHECK(n.powder_mass == Approx(mass).epsilon(1e-12));
  CHECK(z_min > -1.01 * delta_c);
  CHECK(delta_c < 0.1 * r);
  // the yield work: f_y times the permanent overlap r
  CHECK(sys.energies().damping == Approx(f_y * r).epsilon(0.02));
  CHECK(std::abs(sys.energy_balance_error()) < 2e-3);
}

namespace {

// A yielding granule (below the comminution limit) on a floor, squeezed by a tenth of its
// diameter beyond the elastic overlaps under two meshes that describe one surface (a square of
// side 8 d at its top; the second triangulated along the other diagonal, then turned by `turn`),
// which then slide without friction by `slide` over it; `guides`: two frictionless planes at the
// granule's sides in x.
struct TwinMeshes {
  double f_y = 0.0, squeeze = 0.0;
  double damping_squeezed = 0.0, damping = 0.0, balance = 0.0;
  double f_min = 1e300, f_max = 0.0;  // the meshes' force (z) during the slide
  int switches = 0;                   // steps where the mesh that carried the larger force changed
  std::size_t particles = 0;
};
TwinMeshes twin_meshes(const std::function<void(Eigen::MatrixX3d&, double d)>& turn,
                       const Eigen::Vector3d& slide, bool guides = false) {
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3, speed = 0.005, slide_speed = 0.05;
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double e_eff = 1.0 / ((1.0 - NU * NU) / E + (1.0 - NU_P * NU_P) / E_P);
  TwinMeshes out;
  out.f_y = eq2_force(d, b);
  const double delta_y = std::pow(3.0 * out.f_y / (4.0 * e_eff * std::sqrt(0.5 * d)), 2.0 / 3.0);
  out.squeeze = 0.1 * d;
  Eigen::MatrixX3d x0(4, 3);
  x0 << -4 * d, -4 * d, d, 4 * d, -4 * d, d, 4 * d, 4 * d, d, -4 * d, 4 * d, d;
  TriangleMesh::Triangles ta(2, 3), tb(2, 3);
  ta << 0, 1, 2, 0, 2, 3;
  tb << 1, 2, 3, 1, 3, 0;
  System sys;
  const int g = sys.add_material({E, NU, RHO});
  const int s = sys.add_material({E_P, NU_P, 7850.0});
  const int w = sys.add_material({E_P, NU_P, 7850.0});  // the meshes: frictionless
  sys.add_interaction(g, g, {0.3, 0.5, 0.0});
  sys.add_interaction(g, s, {0.3, 0.5, 0.0});
  sys.add_interaction(g, w, {0.0, 0.5, 0.0});
  sys.add_interaction(s, w, {0.0, 0.5, 0.0});
  sys.add_interaction(s, s, {0.0, 0.5, 0.0});
  sys.add_interaction(w, w, {0.0, 0.5, 0.0});
  sys.add_particle({0.3 * d, 0.1 * d, 0.5 * d}, 0.5 * d, g);
  sys.add_plane({0, 0, 0}, {0, 0, 1}, s);
  if (guides) {  // frictionless planes touching the granule's sides at x (it cannot roll along x)
    sys.add_plane({-0.2 * d, 0, 0}, {1, 0, 0}, w);
    sys.add_plane({0.8 * d, 0, 0}, {-1, 0, 0}, w);
  }
  Eigen::MatrixX3d xb0 = x0;
  turn(xb0, d);
  const int ma = sys.add_mesh(x0, ta, w);
  const int mb = sys.add_mesh(xb0, tb, w);
  sys.add_hook(std::make_unique<Breakage>(b));
  sys.set_energy_tracking(true);
  const double dt = 0.2 * sys.rayleigh_time_step();
  const auto move = [&](const Eigen::Vector3d& shift) {
    const Eigen::MatrixX3d ya = x0.rowwise() + shift.transpose();
    const Eigen::MatrixX3d yb = xb0.rowwise() + shift.transpose();
    sys.set_vertex_positions(ma, ya);
    sys.set_vertex_positions(mb, yb);
    sys.step(dt);
  };
  const auto down = static_cast<long>((out.squeeze + 2.0 * delta_y) / (speed * dt));
  for (long k = 0; k < down; ++k)
    move({0.0, 0.0, -speed * dt * static_cast<double>(k + 1)});
  const double z = -speed * dt * static_cast<double>(down);
  out.damping_squeezed = sys.energies().damping;
  const auto across = static_cast<long>(slide.norm() * d / (slide_speed * dt));
  int holder = -1;
  for (long k = 0; k < across; ++k) {
    const Eigen::Vector3d shift =
        (slide_speed * dt * static_cast<double>(k + 1)) * slide.normalized();
    move({shift.x(), shift.y(), z});
    const double fa = sys.mesh_force(ma).norm(), fb = sys.mesh_force(mb).norm();
    const double f = sys.mesh_force(ma).z() + sys.mesh_force(mb).z();
    out.f_min = std::min(out.f_min, f);
    out.f_max = std::max(out.f_max, f);
    const int now = fa > fb ? ma : mb;
    if (holder >= 0 && now != holder) ++out.switches;
    holder = now;
  }
  out.damping = sys.energies().damping;
  out.balance = sys.energy_balance_error();
  out.particles = sys.particle_count();
  return out;
}

// What both variants must give: one contact that keeps its permanent overlap through the slide
void check_twin(const TwinMeshes& r) {
  INFO("f_y " << r.f_y << " N; mesh force during the slide " << r.f_min << " to " << r.f_max
              << " N; the larger force changed mesh " << r.switches
              << " times; yield and damping work " << r.damping_squeezed << " J after the squeeze, "
              << r.damping << " J after the slide (f_y x squeeze " << r.f_y * r.squeeze
              << " J); balance error " << r.balance);
  CHECK(r.particles == 1);
  // the squeeze: f_y times the travel beyond the elastic overlaps
  CHECK(r.damping_squeezed == Approx(r.f_y * r.squeeze).epsilon(0.03));
  // the slide (along the surface) yields no more, and the force stays at the strength's: one
  // contact, not one a mesh
  CHECK(r.damping == Approx(r.damping_squeezed).epsilon(0.02));
  CHECK(r.f_min == Approx(r.f_y).epsilon(0.02));
  CHECK(r.f_max == Approx(r.f_y).epsilon(0.02));
  CHECK(std::abs(r.balance) < 2e-3);
}

}  // namespace

TEST_CASE("dem: a yielding granule under two meshes that coincide keeps its permanent overlap as "
          "its contact passes between them", "[dem][breakage][energy]") {
  // Two meshes of one surface, as two interfaces of one body meet along a shared edge or face
  // (the torn outer plate's surface and its exposed faces): a sphere touches them as one wall.
  // The second mesh tilted by 1e-5 rad about the line x = 1.3 d: one contact (the twin's normal
  // is the same within the tolerance), held by the nearer mesh, which changes where the tilted
  // one crosses the other, 1 d into a slide along x. Its permanent overlap must follow the
  // contact from one mesh to the other, so that the yield work stays f_y times the squeeze's
  // travel and the books close. (A contact that restarted without it would yield again: each
  // change of mesh would book f_y times the permanent overlap once more.)
  const TwinMeshes r = twin_meshes(
      [](Eigen::MatrixX3d& x, double d) {
        x.col(2) = x.col(2).array() + 1.0e-5 * (x.col(0).array() - 1.3 * d);
      },
      {-2.0, 0.7, 0.0});
  CHECK(r.switches > 0);  // the contact did pass between the meshes (else this tests nothing)
  check_twin(r);
}

TEST_CASE("dem: a yielding granule under two meshes of one surface whose normals differ by 2 "
          "degrees touches it once", "[dem][breakage][energy]") {
  // The second mesh turned by 2 degrees about the line over the granule's top along y (a face
  // of one interface and its twin on another, apart by more than the tolerance of equal
  // normals), the slide along that line: both meshes have their point where the granule touches,
  // flush with each other. One contact, as on one mesh: the force stays at f_y (two contacts
  // would carry it twice, each yielding) and the yield work the squeeze's. (Frictionless guides
  // at the granule's sides: the turned face pushes it along x, and it would roll away.)
  const TwinMeshes r = twin_meshes(
      [](Eigen::MatrixX3d& x, double d) {
        const double a = 2.0 * std::numbers::pi / 180.0, x_c = 0.3 * d, z_c = d;
        for (Eigen::Index v = 0; v < x.rows(); ++v) {
          const double u = x(v, 0) - x_c, h = x(v, 2) - z_c;
          x(v, 0) = x_c + std::cos(a) * u - std::sin(a) * h;
          x(v, 2) = z_c + std::sin(a) * u + std::cos(a) * h;
        }
      },
      {0.0, 2.0, 0.0}, true);
  check_twin(r);
}

TEST_CASE("dem: a yielding granule that a mesh is placed or moved into at once dissipates nothing "
          "the mesh did not work for", "[dem][breakage][energy]") {
  // A granule below the comminution limit at rest on a floor; a mesh placed (at rest, velocities
  // zero) into it by 0.15 d at once, as a contact found deep inside another body's surface is:
  // no force has worked on the granule, so its contact's permanent overlap, which yields at the
  // first pass, dissipates nothing (work booked: at most the elastic energy at yield, a small
  // fraction of f_y times the overlap that a yield counted then would book). Its force is then
  // f_y, and pressing on, the yield books f_y times the further travel.
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3;
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double f_y = eq2_force(d, b);
  System sys;
  granule_on_floor(sys, d);
  Eigen::MatrixX3d x0(4, 3);  // a square of side 4 d far above the granule
  x0 << -2 * d, -2 * d, 3 * d, 2 * d, -2 * d, 3 * d, 2 * d, 2 * d, 3 * d, -2 * d, 2 * d, 3 * d;
  TriangleMesh::Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  const int mesh = sys.add_mesh(x0, t, 1);
  sys.add_hook(std::make_unique<Breakage>(b));
  sys.set_energy_tracking(true);
  const double dt = 0.2 * sys.rayleigh_time_step();
  for (int k = 0; k < 10; ++k) sys.step(dt);
  const double before = sys.energies().damping;
  Eigen::MatrixX3d y = x0;
  y.col(2).array() -= 2.0 * d + 0.15 * d;  // its face 0.15 d into the granule's top
  const Eigen::MatrixX3d still = Eigen::MatrixX3d::Zero(4, 3);
  sys.set_vertex_positions(mesh, y, still);
  sys.step(dt);
  const double found = sys.energies().damping - before;
  const double force = sys.mesh_force(mesh).norm();
  // pressing on by 0.05 d at 0.005 m/s: the yield books f_y per unit travel
  const double speed = 0.005;
  const auto steps = static_cast<long>(0.05 * d / (speed * dt));
  for (long k = 0; k < steps; ++k) {
    y.col(2).array() -= speed * dt;
    sys.set_vertex_positions(mesh, y, Eigen::MatrixX3d((Eigen::MatrixX3d(4, 3) << 0, 0, -speed, 0, 0, -speed, 0, 0, -speed, 0, 0, -speed).finished()));
    sys.step(dt);
  }
  const double pressed = sys.energies().damping - before - found;
  // moved on by 0.1 d at once, at rest again (the contact carried on its feature: a geometry
  // that jumps, as a particle inside a thin part whose way out passes to a deeper face): the
  // permanent overlap takes the jump, no work was done for it
  const double before_jump = sys.energies().damping;
  y.col(2).array() -= 0.1 * d;
  sys.set_vertex_positions(mesh, y, still);
  sys.step(dt);
  const double jumped = sys.energies().damping - before_jump;
  INFO("f_y " << f_y << " N; force after the placing " << force << " N; yield and damping work at "
              << "the placing " << found << " J (f_y x 0.15 d = " << f_y * 0.15 * d
              << " J), pressing on by 0.05 d " << pressed << " J (f_y x 0.05 d = "
              << f_y * 0.05 * d << " J), the jump by 0.1 d " << jumped << " J");
  CHECK(sys.particle_count() == 1);
  CHECK(force == Approx(f_y).epsilon(0.02));
  CHECK(found < 0.05 * f_y * 0.15 * d);
  CHECK(pressed == Approx(f_y * 0.05 * d).epsilon(0.1));
  CHECK(std::abs(jumped) < 0.05 * f_y * 0.1 * d);
  CHECK(sys.mesh_force(mesh).norm() == Approx(f_y).epsilon(0.02));
}

TEST_CASE("dem: below the comminution limit two granules that collide yield and rebound at the "
          "yield velocity", "[dem][breakage][energy]") {
  // Two equal granules below the comminution limit (below_limit yield), no damping (restitution
  // 1), head on at v. Their contact's mean pressure is held at their strength sigma: elastic up
  // to delta_y = R* (3 pi sigma / (4 E*))^2, where it carries F_y = 4/3 E* sqrt(R*) delta_y^1.5
  // and stores W_y = 2/5 F_y delta_y; beyond, the overlap becomes permanent and F_y's work is
  // dissipated. Unloading gives back W_y only, so the granules part at the yield velocity
  // v_y = sqrt(2 W_y / m*): restitution v_y / v, the rest of the kinetic energy dissipated.
  // The state written mid-contact (the permanent overlap with it) resumes to the same bits.
  const double d = 2.0e-3, v = 3.5;
  BreakageParameters b = parameters(3.0);
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double sigma = b.limit_strength;  // d = d0
  const double e_star = E / (2.0 * (1.0 - NU * NU)), r_star = 0.25 * d;
  const double root = 0.75 * std::numbers::pi * sigma / e_star;
  const double delta_y = r_star * root * root;
  const double f_y = 4.0 / 3.0 * e_star * std::sqrt(r_star) * std::pow(delta_y, 1.5);
  const double mass = test::sphere_mass(0.5 * d, RHO), m_star = 0.5 * mass;
  const double v_y = std::sqrt(2.0 * 0.4 * f_y * delta_y / m_star);
  REQUIRE(v_y < 0.5 * v);
  const auto setup = [&](System& sys, bool yield) {
    b.yield = yield;
    const int g = sys.add_material({E, NU, RHO});
    sys.add_interaction(g, g, {0.0, 1.0, 0.0});
    sys.add_particle({-0.5 * d - 1e-6, 0, 0}, 0.5 * d, g);
    sys.add_particle({0.5 * d + 1e-6, 0, 0}, 0.5 * d, g);
    sys.set_particle_velocity(0, {0.5 * v, 0, 0});
    sys.set_particle_velocity(1, {-0.5 * v, 0, 0});
    sys.add_hook(std::make_unique<Breakage>(b));
    sys.set_energy_tracking(true);
  };
  System sys;
  setup(sys, true);
  const double dt = 0.05 * sys.rayleigh_time_step();
  const long steps = static_cast<long>(4.0 * 0.5 * d / v / dt);  // long after they part
  std::stringstream mid;
  double deepest = 0.0;
  long written = -1;  // the step after which the state was written (yielding)
  for (long k = 0; k < steps; ++k) {
    sys.step(dt);
    const Particles& p = sys.particles();
    deepest = std::max(deepest, d - (p.position[1] - p.position[0]).norm());
    if (written < 0 && deepest > 2.0 * delta_y) {
      sys.write_state(mid);
      written = k;
    }
  }
  REQUIRE(written > 0);
  const Particles& p = sys.particles();
  const double rebound = p.velocity[1].x() - p.velocity[0].x();
  const double ke_in = 0.5 * m_star * v * v;
  INFO("v_y " << v_y << " m/s, rebound " << rebound << " m/s; deepest overlap " << deepest
              << " m, delta_y " << delta_y << " m; dissipated " << sys.energies().damping
              << " J of " << ke_in << " J; balance error " << sys.energy_balance_error());
  REQUIRE(sys.particle_count() == 2);
  CHECK(breakage_of(sys).counters().events == 0);
  CHECK(p.mass[0] == Approx(mass).epsilon(1e-12));
  CHECK(rebound == Approx(v_y).epsilon(0.01));
  // the deepest overlap: F_y (deepest - delta_y) + W_y = the kinetic energy of the approach
  CHECK(deepest == Approx(delta_y + (ke_in - 0.4 * f_y * delta_y) / f_y).epsilon(0.01));
  CHECK(sys.energies().damping == Approx(ke_in - 0.5 * m_star * v_y * v_y).epsilon(0.01));
  CHECK(std::abs(sys.energy_balance_error()) < 1e-3);
  // resumed from the state written mid-contact: the same bits
  System resumed;
  setup(resumed, true);
  resumed.read_state(mid);
  for (long k = written + 1; k < steps; ++k) resumed.step(dt);
  CHECK(resumed.particles().velocity[1].x() == p.velocity[1].x());
  CHECK(resumed.particles().position[1].x() == p.position[1].x());
  // elastic granules (below_limit unbreakable) rebound at the speed they came
  System elastic;
  setup(elastic, false);
  for (long k = 0; k < steps; ++k) elastic.step(dt);
  const Particles& q = elastic.particles();
  CHECK(q.velocity[1].x() - q.velocity[0].x() == Approx(v).epsilon(0.01));
}

TEST_CASE("dem: a bed of fragments that yield against each other keeps its energy books",
          "[dem][breakage][energy]") {
  // ~400 granules below the comminution limit (below_limit yield) in a box, pressed by a lid
  // to a fifth of their size of overlap, on 1 and 2 threads (the cross pairs of two parts): the
  // lid's work goes into the contacts' elastic energy, damping and the pairs' yield (booked with
  // the damping); the books close as they do for the elastic bed (|error| < 1e-3), and the yield
  // work is a real part of them.
  const double d1 = 1.0e-3, d2 = 1.5e-3, side = 8.0e-3, speed = 0.2;
  for (int threads : {1, 2})
    for (bool yield : {true, false}) {
      set_num_threads(threads);
      BreakageParameters b = parameters(3.0);
      b.comminution_limit = 2.0e-3;
      b.yield = yield;
      System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
      const Packing pk = test::two_size_packing({0, 0, 0}, {side, side, side}, d1, d2, 0.5, 7);
      sys.add_particles(pk.positions, pk.radii, 0);
      sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
      sys.add_plane({0, 0, 0}, {1, 0, 0}, 0);
      sys.add_plane({0, 0, 0}, {0, 1, 0}, 0);
      sys.add_plane({side, 0, 0}, {-1, 0, 0}, 0);
      sys.add_plane({0, side, 0}, {0, -1, 0}, 0);
      const int lid = sys.add_plane({0, 0, side}, {0, 0, -1}, 0, {0, 0, -speed});
      sys.add_hook(std::make_unique<Breakage>(b));
      sys.set_energy_tracking(true);
      const double dt = 0.2 * sys.rayleigh_time_step();
      const long steps = static_cast<long>(0.25 * side / speed / dt);  // the lid down by a quarter
      double worst = 0.0;  // over the second half (the error is relative to the work done)
      for (long k = 0; k < steps; ++k) {
        sys.step(dt);
        if (2 * k > steps) worst = std::max(worst, std::abs(sys.energy_balance_error()));
      }
      const System::Energies& e = sys.energies();
      INFO(threads << " thread(s), yield " << yield << ": " << sys.particle_count()
                   << " particles, lid work " << e.wall_work[static_cast<std::size_t>(lid)]
                   << " J, damping " << e.damping << " J, friction " << e.friction
                   << " J, elastic " << sys.elastic_energy() << " J, worst balance error " << worst);
      CHECK(sys.particle_count() == static_cast<std::size_t>(pk.radii.size()));
      CHECK(worst < 1e-3);
      if (yield) CHECK(e.damping > 0.2 * e.wall_work[static_cast<std::size_t>(lid)]);
    }
  set_num_threads(1);
}

TEST_CASE("dem: breakage conserves momentum and does not create kinetic energy",
          "[dem][breakage]") {
  for (const std::string& pattern : FragmentPattern::names())
    for (bool restore : {false, true}) {
      BreakageParameters b = parameters(5.0);
      b.pattern = FragmentPattern::named(pattern).kind();
      b.restore_mass = restore;
      System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
      const double r = 1.5e-3;
      const Eigen::Vector3d x0(1e-3, -2e-3, 3e-3), v0(0.3, -0.2, 0.5), w0(40.0, -25.0, 60.0);
      sys.add_particle(x0, r, 0, v0, w0);
      sys.add_hook(std::make_unique<Breakage>(b));
      const Motion before(sys, x0);
      breakage_of(sys).break_particles(sys, {0});
      const Motion after(sys, x0);
      const Particles& p = sys.particles();
      INFO(pattern << (restore ? ", mass restored" : ", mass lost") << ": " << p.size()
                   << " fragments holding " << after.mass / before.mass << " of the mass");
      REQUIRE(p.size() == static_cast<std::size_t>(FragmentPattern::named(pattern).size()));
      // inscribed: inside the parent, not touching each other
      for (std::size_t i = 0; i < p.size(); ++i) {
        CHECK((p.position[i] - x0).norm() + p.radius[i] < r);
        for (std::size_t j = i + 1; j < p.size(); ++j)
          CHECK((p.position[i] - p.position[j]).norm() > p.radius[i] + p.radius[j]);
      }
      const BreakageCounters& c = breakage_of(sys).counters();
      if (restore) {
        CHECK(after.mass == Approx(before.mass).epsilon(1e-14));
        CHECK((after.p - before.p).norm() <= 1e-14 * before.p.norm());
        CHECK((after.l - before.l).norm() <= 1e-12 * before.l.norm());
        CHECK(after.ke == Approx(before.ke).epsilon(1e-12));
        CHECK(c.mass_restored == Approx(before.mass - c.fragment_mass + c.mass_restored));
      } else {
        // the lost mass takes its share of the momentum: the fragments keep the parent's velocity
        // of the centre of mass, and they rotate rigidly with it
        CHECK(c.mass_lost == Approx(before.mass - after.mass).epsilon(1e-12));
        CHECK((after.p - after.mass * v0).norm() <= 1e-14 * before.p.norm());
        Eigen::Vector3d l_rigid = Eigen::Vector3d::Zero();
        for (std::size_t i = 0; i < p.size(); ++i) {
          const Eigen::Vector3d c_i = p.position[i] - x0;
          l_rigid += p.mass[i] * (c_i.squaredNorm() * w0 - c_i * c_i.dot(w0)) + p.inertia[i] * w0;
        }
        CHECK((after.l - l_rigid).norm() <= 1e-12 * before.l.norm());
        CHECK(after.ke <= before.ke);
      }
      CHECK(c.events == 1);
    }
}

TEST_CASE("dem: kinetic energy after breakage does not exceed kinetic plus released elastic",
          "[dem][breakage]") {
  BreakageParameters b = parameters(3.0);
  b.comminution_limit = 1.0;  // nothing breaks by itself: break by hand at 90 % of the load
  const double d = 2.0e-3;
  Platens t(d, b, 0.005);
  const double dt = 0.2 * t.sys.rayleigh_time_step();
  while (t.sys.wall_force(t.top).norm() < 0.9 * eq2_force(d, parameters(3.0))) t.sys.step(dt);
  const double ke0 = t.sys.kinetic_energy(), el0 = t.sys.elastic_energy();
  breakage_of(t.sys).break_particles(t.sys, {0});
  const double ke1 = t.sys.kinetic_energy(), el1 = t.sys.elastic_energy();
  INFO("KE " << ke0 << " -> " << ke1 << " J, elastic " << el0 << " -> " << el1 << " J");
  CHECK(el1 < el0);  // fragments overlap the platens less than the parent did
  CHECK(ke1 <= ke0 + (el0 - el1));
}

TEST_CASE("dem: drawn strengths follow the declared Weibull law (Kolmogorov-Smirnov, 1 %)",
          "[dem][breakage]") {
  const int n = 10000;
  const double critical = 1.628 / std::sqrt(static_cast<double>(n));  // 1 % level, large n
  for (double m : {3.0, 10.0})
    for (double d : {2.0e-3, 5.0e-3}) {
      const BreakageParameters b = parameters(m, true);
      const Breakage model(b);
      const double sigma_c = 30.0e6 * std::pow(d / 2.0e-3, -3.0 / m);
      std::vector<double> s(n);
      for (int k = 0; k < n; ++k) s[k] = model.draw_strength(k, d);
      std::sort(s.begin(), s.end());
      double ks = 0.0;
      for (int k = 0; k < n; ++k) {
        const double f = 1.0 - std::exp(-std::pow(s[k] / sigma_c, m));  // Weibull CDF
        ks = std::max({ks, std::abs(f - static_cast<double>(k) / n),
                       std::abs(f - static_cast<double>(k + 1) / n)});
      }
      INFO("m " << m << ", d " << d << ": D = " << ks << ", critical " << critical);
      CHECK(ks < critical);
      CHECK(model.draw_strength(17, d) == Breakage(b).draw_strength(17, d));  // reproducible
    }
  BreakageParameters other = parameters(3.0, true);
  other.seed = 2;
  CHECK(Breakage(other).draw_strength(17, 2e-3) !=
        Breakage(parameters(3.0, true)).draw_strength(17, 2e-3));
}

namespace {

// A bed dropped onto a floor with weak granules: some break on landing.
System crushing_bed(double box) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.0});
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(Eigen::Vector3d(0, 0, 1e-3),
                                            Eigen::Vector3d(box, box, box), 1.2e-3, 0.8e-3, 0.6, 9);
  sys.add_particles(pk.positions, pk.radii, m);
  for (std::size_t i = 0; i < sys.particle_count(); ++i) sys.set_particle_velocity(i, {0, 0, -0.5});
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2 * box), m, 0b011111);
  BreakageParameters b;
  b.limit_strength = 0.4e6;
  b.reference_size = 1e-3;
  b.weibull_modulus = 3.0;
  b.comminution_limit = 0.5e-3;
  sys.add_hook(std::make_unique<Breakage>(b));
  return sys;
}

bool same_particles(const System& a, const System& b) {
  const Particles& p = a.particles();
  const Particles& q = b.particles();
  return p.id == q.id && p.position == q.position && p.velocity == q.velocity &&
         p.angular_velocity == q.angular_velocity && p.force == q.force && p.radius == q.radius &&
         p.mass == q.mass;
}

}  // namespace

TEST_CASE("dem: with breakage on, results do not depend on the number of threads",
          "[dem][breakage][threads]") {
  auto run = [](int threads) {
    set_num_threads(threads);
    System sys = crushing_bed(14e-3);
    const double dt = 0.2 * sys.rayleigh_time_step();
    for (int s = 0; s < 400; ++s) sys.step(std::min(dt, 0.2 * sys.rayleigh_time_step()));
    return sys;
  };
  const int before = max_threads();
  System one = run(1);
  System two = run(2);
  set_num_threads(before);
  const BreakageCounters& c = breakage_of(one).counters();
  INFO(one.particle_count() << " particles, " << c.events << " breakage events");
  CHECK(c.events > 0);
  CHECK(one.particle_count() > 1024);
  CHECK(same_particles(one, two));
  CHECK(breakage_of(two).counters().events == c.events);
  CHECK(breakage_of(two).counters().energy_released == c.energy_released);
}

TEST_CASE("dem: a repeated window restores the pre-breakage particle set bit for bit",
          "[dem][breakage][state]") {
  System sys = crushing_bed(6e-3);
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(20, dt);
  const std::size_t n0 = sys.particle_count();
  const SystemState saved = sys.save_state();
  std::stringstream file;
  sys.write_state(file);
  const std::int64_t events0 = breakage_of(sys).counters().events;
  // The window (about 10 ms) covers the bed's landing on the floor at 0.5 m/s, where granules
  // break.
  auto window = [&](System& s) {
    for (int k = 0; k < 1500; ++k) s.step(std::min(dt, 0.2 * s.rayleigh_time_step()));
  };
  window(sys);
  INFO("events " << events0 << " -> " << breakage_of(sys).counters().events << ", particles " << n0);
  REQUIRE(breakage_of(sys).counters().events > events0);
  const System first = sys;
  sys.restore_state(saved);
  CHECK(sys.particle_count() == n0);
  CHECK(breakage_of(sys).counters().events == events0);
  window(sys);
  CHECK(same_particles(sys, first));
  CHECK(breakage_of(sys).counters().mass_lost == breakage_of(first).counters().mass_lost);
  // and from a restart file, into a system set up alike
  System fresh = crushing_bed(6e-3);
  fresh.read_state(file);
  window(fresh);
  CHECK(same_particles(fresh, first));
}

TEST_CASE("dem: fragments are further breakable and the stable step follows them",
          "[dem][breakage]") {
  BreakageParameters b = parameters(3.0);
  b.pattern = FragmentPattern::Kind::equal_4;
  b.comminution_limit = 0.5e-3;
  Platens t(4.0e-3, b, 0.05);
  const double dt0 = t.sys.rayleigh_time_step();
  long steps = 0;
  while (breakage_of(t.sys).counters().events < 2 && steps < 2'000'000) {
    t.sys.step(0.2 * t.sys.rayleigh_time_step());
    ++steps;
  }
  const BreakageCounters& c = breakage_of(t.sys).counters();
  INFO(c.events << " events, " << t.sys.particle_count() << " particles, smallest fragment "
                << c.smallest_fragment);
  CHECK(c.events >= 2);  // a fragment broke again
  // Rayleigh step proportional to the smallest radius: equal-4 fragments have 0.4495 R
  double r_min = 1.0;
  for (double r : t.sys.particles().radius) r_min = std::min(r_min, r);
  CHECK(t.sys.rayleigh_time_step() == Approx(dt0 * r_min / 2.0e-3).epsilon(1e-9));
  CHECK(c.smallest_fragment == Approx(2.0 * r_min));
}

TEST_CASE("dem: a breakage model added after the first steps takes over at once",
          "[dem][breakage]") {
  const BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3;
  Platens with(d, b, 0.005);  // hook from the start
  // the same set-up without the hook
  System plain;
  granule_on_floor(plain, d);
  const int top = plain.add_plane({0, 0, d}, {0, 0, -1}, 1, {0, 0, -0.005});
  const double dt = 0.2 * plain.rayleigh_time_step();
  plain.run(50, dt);
  with.sys.run(50, dt);
  plain.add_hook(std::make_unique<Breakage>(b));
  long steps = 50;
  while (breakage_of(plain).counters().events == 0 && steps < 2'000'000) {
    plain.step(dt);
    with.sys.step(dt);
    ++steps;
  }
  CHECK(breakage_of(plain).counters().events == 1);
  CHECK(breakage_of(with.sys).counters().events == 1);  // the same step
  CHECK(plain.wall_force(top).norm() == Approx(eq2_force(d, b)).epsilon(0.01));
}

TEST_CASE("dem: grading is the cumulative mass fraction passing each size", "[dem][breakage]") {
  System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
  sys.add_particle({0, 0, 0}, 1e-3, 0);    // d = 2 mm, mass 8 units
  sys.add_particle({1, 0, 0}, 0.5e-3, 0);  // d = 1 mm, 1 unit each
  sys.add_particle({2, 0, 0}, 0.5e-3, 0);
  const auto g = Grading::cumulative(sys.particles());
  REQUIRE(g.size() == 2);
  CHECK(g[0].size == 1e-3);
  CHECK(g[0].passing == Approx(2.0 / 10.0));
  CHECK(g[1].passing == 1.0);
  const auto p = Grading::passing(sys.particles(), {0.5e-3, 1.5e-3, 3e-3});
  CHECK(p[0] == 0.0);
  CHECK(p[1] == Approx(0.2));
  CHECK(p[2] == Approx(1.0));
}

TEST_CASE("dem: breakage parameters out of range are refused", "[dem][breakage][errors]") {
  for (int k = 0; k < 4; ++k) {
    BreakageParameters b = parameters(3.0);
    (k == 0   ? b.limit_strength
     : k == 1 ? b.reference_size
     : k == 2 ? b.weibull_modulus
              : b.comminution_limit) = -1.0;
    CHECK_THROWS_AS(Breakage(b), Error);
  }
  BreakageParameters both = parameters(3.0);
  both.powder = both.yield = true;
  CHECK_THROWS_WITH(Breakage(both), Catch::Contains("powder or yields"));
  CHECK_THROWS_WITH(FragmentPattern::named("apolonian-14"), Catch::Contains("apollonian-14"));
  System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
  sys.add_hook(std::make_unique<Breakage>(parameters(3.0)));
  CHECK_THROWS_AS(sys.add_hook(std::make_unique<Breakage>(parameters(3.0))), Error);
}

namespace {

// A hook with a load limit per particle (as Breakage has), the same for every particle.
class LimitHook final : public StepHook {
 public:
  explicit LimitHook(double limit) : limit_(limit) {}
  std::string name() const override { return "limit"; }
  std::unique_ptr<StepHook> clone() const override { return std::make_unique<LimitHook>(*this); }
  void attach(System& system) override {
    h_ = system.store_unsynced().add_array<double>("test_load_limit", 1, limit_);
  }
  bool wants_contact_load() const override { return true; }
  int contact_load_limit() const override { return h_; }
  void end_of_step(System& system, double) override { reached_ = system.contact_load_reached(); }
  bool reached_ = false;

 private:
  double limit_;
  int h_ = -1;
};

}  // namespace

TEST_CASE("dem: the force pass reports a contact load that reaches a hook's limit",
          "[dem][breakage][slow]") {
  // A sphere at rest on a plane under gravity: the contact force is its weight m g (static
  // equilibrium), so its load is m g (E*/R)^2 (wall: R* = R). The other particles are far away
  // and touch nothing (their loads are 0). A limit 1 % above the load is not reached, 1 % below
  // it is; so is a limit of 0 (>= includes a load of 0) and not one of +infinity.
  const double r = 1e-3, g = 9.81;
  const double e_star = 1.0 / (2.0 * (1.0 - NU * NU) / E);
  const double load = test::sphere_mass(r, RHO) * g * (e_star / r) * (e_star / r);
  for (int threads : {1, 2})
    for (double factor : {1.01, 0.99, 0.0, HUGE_VAL}) {
      set_num_threads(threads);
      System sys = test::single_material(E, NU, RHO, 0.5, 0.3);
      sys.set_gravity({0, 0, -g});
      const int k = sys.add_hook(std::make_unique<LimitHook>(factor * load));
      // rows of spheres apart (enough for two parts) and one resting on the floor
      sys.add_particle({0, 0, r}, r, 0);
      for (int i = 1; i < 2100; ++i) sys.add_particle({0.01 * i, 0, 0.5}, r, 0);
      sys.add_plane({0, 0, 0}, {0, 0, 1}, 0);
      const double dt = 0.2 * sys.rayleigh_time_step();
      for (int s = 0; s < 3000; ++s) sys.step(dt);  // settles (e = 0.5)
      // the far particles fall freely: give them no time to reach the floor
      INFO(threads << " thread(s), limit " << factor << " x the load; load "
                   << sys.contact_load()[0] << ", m g (E*/R)^2 " << load);
      REQUIRE(sys.contact_load()[0] == Approx(load).epsilon(1e-3));
      const bool reached = static_cast<const LimitHook&>(sys.hook(k)).reached_;
      CHECK(reached == (factor <= 0.99));
    }
  set_num_threads(1);
}

TEST_CASE("dem: the energy balance closes across a breakage event", "[dem][breakage][energy]") {
  // The platen's work goes into the granule's contacts until it breaks; the fragments (inscribed,
  // lighter than the parent: apollonian-14 keeps part of the mass) take less than the parent had,
  // and the difference is the breakage energy: KE + E_el before minus after the replacement.
  const BreakageParameters b = parameters(3.0);
  Platens t(2.0e-3, b, 0.005);
  t.sys.set_energy_tracking(true);
  const double dt = 0.2 * t.sys.rayleigh_time_step();
  long steps = 0;
  double last = 0.0;  // the balance error before the event
  for (; steps < 2'000'000 && breakage_of(t.sys).counters().events == 0; ++steps) {
    last = t.sys.energy_balance_error();
    t.sys.step(dt);
  }
  REQUIRE(breakage_of(t.sys).counters().events == 1);
  const System::Energies& e = t.sys.energies();
  // right after the step whose hook broke the granule (what a coupling window reads): the change
  // is booked already (provisionally: the next step's start adds what its force pass changes)
  const double at_event = t.sys.energy_balance_error();
  const double breakage_at_event = e.breakage;
  t.sys.step(dt);
  const double next = t.sys.energy_balance_error();
  const double before = t.sys.energy_balance_error();  // (the event's change is pending)
  t.sys.run(2000, dt);
  const double work = e.wall_work[static_cast<std::size_t>(t.top)];
  INFO("broke after " << steps << " steps; platen work " << work << " J, breakage "
                      << e.breakage << " J, friction " << e.friction << " J, damping " << e.damping
                      << " J, elastic " << t.sys.elastic_energy() << " J, balance error "
                      << t.sys.energy_balance_error() << " (" << last << " before the event, " << before
                      << " before the next step, " << next << " after it, " << at_event
                      << " right after the event's step, breakage then " << breakage_at_event
                      << " J)");
  CHECK(work > 0.0);
  CHECK(e.breakage > 0.0);
  CHECK(e.breakage < work);
  // before the event the platen's loading balances to 4e-6; after it, the platen's work over the
  // half step after the last pass, counted with the parent's force (1/2 dt F u, F the breaking
  // force), stays in the balance: the change is settled before a pass gives the plane forces on
  // the new set (1.3e-3 of the work here: half of one step's work against ~960 steps of loading)
  CHECK(std::abs(last) < 1e-4);
  CHECK(std::abs(at_event) < 2e-3);
  CHECK(breakage_at_event > 0.0);
  CHECK(std::abs(next) < 2e-3);
  CHECK(std::abs(t.sys.energy_balance_error()) < 2e-3);
}

TEST_CASE("dem: removing a particle high above the origin leaves the energy books closed",
          "[dem][breakage][energy]") {
  // Two spheres fall freely 10 m above the origin; one is removed mid-fall (as powder is). The
  // books take gravity's work from the motion, so the removed sphere's kinetic energy is all the
  // change books: the balance stays at rounding, wherever the origin lies. (Booked with its
  // potential energy -m g . x, it was off by m g z = 10 m of fall against 0.05 m fallen.)
  for (const double z0 : {0.0, 10.0}) {
    System sys;
    const int m = sys.add_material({1.0e7, 0.3, 2500.0});
    sys.add_interaction(m, m, {0.5, 0.5, 0.0});
    sys.set_gravity({0, 0, -9.81});
    sys.add_particle({0, 0, z0}, 1e-3, m);
    sys.add_particle({0.01, 0, z0}, 1e-3, m, {0, 0, 0.3});
    sys.set_energy_tracking(true);
    const double dt = 1e-5;
    sys.run(5000, dt);  // (0.05 s: 12 mm fallen)
    sys.remove_particles({0, 1});
    sys.run(5000, dt);
    INFO("origin " << z0 << " m below the start: balance " << sys.energy_balance_error()
                   << ", breakage " << sys.energies().breakage << " J");
    CHECK(std::abs(sys.energy_balance_error()) < 1e-9);
    // what left with the sphere: its kinetic energy at the leapfrog's half step, 1/2 m v^2 with
    // v = 0.3 m/s - g t - g dt/2 (what the books take as kinetic energy: KE + the half-step term)
    const double mass = 2500.0 * 4.0 / 3.0 * std::numbers::pi * 1e-9;
    const double v = 0.3 - 9.81 * 0.05 - 9.81 * 0.5 * dt;
    CHECK(sys.energies().breakage == Approx(0.5 * mass * v * v).epsilon(1e-9));
  }
}

TEST_CASE("dem: a read state's load limits follow the breakage rule of the reader, not the stored "
          "ones", "[dem][breakage][restart]") {
  // The limits are derived from the strengths drawn (Breakage::restored()): a state whose
  // stored limits follow another rule (here: every one made infinite before writing, as an
  // unbreakable fine's) resumes with eq. 2's for a breakable granule and 1.5^3 times eq. 2's
  // for a yielding one, and then with the same limits as the system that wrote it.
  BreakageParameters b = parameters(3.0);
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  System sys;
  granule_on_floor(sys, 2.0e-3);                                      // below the limit: yields
  sys.add_particle({0.01, 0, 1.5e-3}, 1.5e-3, 0);                     // 3 mm: breakable
  sys.add_hook(std::make_unique<Breakage>(b));
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(5, dt);  // (strengths drawn at the first pass)
  const int h = sys.store().find("breakage_load_limit");
  const int hs = sys.store().find("breakage_strength");
  REQUIRE(h >= 0);
  REQUIRE(hs >= 0);
  const std::vector<double> limits = sys.store().array<double>(h);
  const std::vector<double> strength = sys.store().array<double>(hs);
  const double pi3 = std::numbers::pi * std::numbers::pi * std::numbers::pi;
  const auto eq2 = [&](std::size_t i) { return 9.0 / 16.0 * pi3 * std::pow(strength[i], 3); };
  REQUIRE(limits.size() == 2);
  CHECK(limits[0] == Approx(3.375 * eq2(0)).epsilon(1e-12));
  CHECK(limits[1] == Approx(eq2(1)).epsilon(1e-12));
  for (double& l : sys.store_unsynced().array<double>(h)) l = std::numeric_limits<double>::infinity();
  std::stringstream state;
  sys.write_state(state);
  System copy;
  granule_on_floor(copy, 2.0e-3);
  copy.add_particle({0.01, 0, 1.5e-3}, 1.5e-3, 0);
  copy.add_hook(std::make_unique<Breakage>(b));
  copy.read_state(state);
  CHECK(copy.store().array<double>(h) == limits);
}

TEST_CASE("dem: a yielding granule pinched between two parts of one one-sided mesh closing on it "
          "is crushed to powder between them, never pushed into either", "[dem][breakage]") {
  // Two steel blocks of one one-sided mesh (as the faces of a slot in a web collapsing on a
  // fragment): the lower one fixed, the upper one coming down slowly onto a granule below the
  // comminution limit resting on the lower one. Both contacts yield at f_y; once their overlaps
  // add up to more than the radius (the faces closer than the radius) the granule is crushed to
  // powder, its centre between the faces all along. (Without the rule it was held at f_y until
  // the gap closed, flattened to nothing, and as a sphere could be pushed into either part.)
  BreakageParameters b = parameters(3.0);
  const double d = 2.0e-3, r = 0.5 * d, speed = 0.005;
  b.comminution_limit = 2.5e-3;
  b.yield = true;
  const double f_y = eq2_force(d, b);
  System sys;
  const int g = sys.add_material({E, NU, RHO});
  const int s = sys.add_material({E_P, NU_P, 7850.0});
  sys.add_interaction(g, g, {0.3, 0.5, 0.0});
  sys.add_interaction(g, s, {0.3, 0.5, 0.0});
  sys.add_particle({0.1 * d, 0.2 * d, r}, r, g);
  const double a = 4.0 * d;
  const auto block = [&](Eigen::MatrixX3d& x, TriangleMesh::Triangles& t, int k, double z0) {
    const int quads[6][4] = {{4, 5, 7, 6}, {0, 2, 3, 1}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int c = 0; c < 8; ++c)
      x.row(8 * k + c) << ((c & 1) ? a : -a), ((c & 2) ? a : -a), z0 + ((c & 4) ? a : 0.0);
    for (int f = 0; f < 6; ++f) {
      t.row(12 * k + 2 * f) << 8 * k + quads[f][0], 8 * k + quads[f][1], 8 * k + quads[f][2];
      t.row(12 * k + 2 * f + 1) << 8 * k + quads[f][0], 8 * k + quads[f][2], 8 * k + quads[f][3];
    }
  };
  Eigen::MatrixX3d x0(16, 3);
  TriangleMesh::Triangles t(24, 3);
  block(x0, t, 0, -a);  // lower: top face z = 0
  block(x0, t, 1, d);   // upper: bottom face z = d, touching the granule's top
  const int mesh = sys.add_mesh(x0, t, s);
  sys.set_mesh_one_sided(mesh, true);
  sys.add_hook(std::make_unique<Breakage>(b));
  const double dt = 0.2 * sys.rayleigh_time_step();
  const auto steps = static_cast<long>(0.95 * d / (speed * dt));  // to a gap of 0.05 d
  Eigen::MatrixX3d y = x0;
  double gap_at_crush = -1.0, z_min = 1.0, behind = -1.0;
  for (long k = 0; k < steps; ++k) {
    const double gap = d - speed * dt * static_cast<double>(k + 1);
    for (int c = 8; c < 16; ++c) y(c, 2) = x0(c, 2) - (d - gap);
    sys.set_vertex_positions(mesh, y);
    sys.step(dt);
    if (sys.particle_count() == 0) {
      gap_at_crush = gap;
      break;
    }
    const double z = sys.particles().position[0].z();
    z_min = std::min(z_min, z);
    behind = std::max(behind, z - gap);
  }
  const BreakageCounters& n = breakage_of(sys).counters();
  INFO("f_y " << f_y << " N; crushed at a gap of " << gap_at_crush << " m (diameter " << d
              << " m); the centre " << z_min << " m above the lower face at least, " << behind
              << " m from the upper one at most; powder " << n.powder_events);
  REQUIRE(gap_at_crush > 0.0);
  CHECK(n.powder_events == 1);
  CHECK(n.powder_mass == Approx(test::sphere_mass(r, RHO)).epsilon(1e-12));
  // crushed once the overlaps add to r: the gap d - r, less the elastic overlaps at f_y
  CHECK(gap_at_crush < r);
  CHECK(gap_at_crush > 0.9 * r);
  CHECK(z_min > 0.0);
  CHECK(behind < 0.0);
}
