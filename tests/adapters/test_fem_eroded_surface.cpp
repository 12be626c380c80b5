// Eroded elements leave the DEM's contact surfaces: the FE participant writes
// "attached" per triangle of an interface (its mesh N_centres), 0 once the element under the
// triangle is eroded; a DEM that took the interface as a wall reads it on its M_centres and
// drops those triangles, so a granule resting on the FE face falls through where the hull has
// ruptured. Here the two adapters are joined by hand, as the core joins them (the mesh handed
// over at set-up, the field copied: the DEM's centres are the FE's triangles' centroids, in the
// same order).
#include <catch2/catch.hpp>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <Eigen/Geometry>

#include "../support/adapter_solver.hpp"

using namespace partita;
namespace fs = std::filesystem;

namespace {

// tests/inputs/fem/strip_rupture.yaml's strip (three Hex8 along x, J2, eps_f = 0.02, pulled
// until every element fails at 33.14 ms) with erosion, its top face z = 0.05 an interface.
const char* kStrip = R"(
solver: fem
mesh: {box: {origin: [0, 0, 0], size: [0.3, 0.05, 0.05], cells: [3, 1, 1]}, element: hex8}
material:
  model: j2-plasticity
  youngs_modulus: 210 GPa
  poisson_ratio: 0.3
  density: 7850
  yield_stress: 250 MPa
  hardening_modulus: 2 GPa
  failure: {criterion: constant, strain: 0.02, erosion: true}
constraints: [{set: xmin, fix: [x]}, {set: ymin, fix: [y]}, {set: zmin, fix: [z]}]
loads: [{face: xmax, traction: [350 MPa, 0, 0], ramp: 0.04}]
interfaces: [{name: top, face: zmax}]
analysis: {type: transient, integrator: central-difference, mass: lumped}
)";

}  // namespace

TEST_CASE("eroded surface: a granule on an FE face falls through once the element is eroded",
          "[adapters][fem][dem][rupture]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_eroded_surface_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto fe = test::make_solver("fem", kStrip, dir, dir);
  const InterfaceMesh& top = test::find_mesh(*fe, "top");
  const InterfaceMesh& centres = test::find_mesh(*fe, "top_centres");
  // one point per triangle of "top", at its centroid, writing "attached"
  REQUIRE(centres.mesh.size() == top.mesh.num_triangles());
  CHECK((centres.mesh.points() - top.mesh.triangle_centroids()).cwiseAbs().maxCoeff() < 1e-15);
  REQUIRE(centres.writes.size() == 1);
  CHECK(centres.writes[0].name == "attached");
  Eigen::MatrixXd intact;
  fe->write("top_centres", "attached", intact);
  CHECK((intact.array() == 1.0).all());

  // the FE strip pulled to rupture
  const double dt = 0.9 * fe->stable_time_step();
  while (test::monitor_value(*fe, "failed_elements") < 1.0 && fe->time() < 0.035) fe->advance(dt);
  const double failed = test::monitor_value(*fe, "failed_elements");
  INFO("t = " << fe->time() << " s, failed elements " << failed);
  REQUIRE(failed >= 1.0);
  // sigma_y + H eps_f = 290 MPa reached on the ramp (dynamics: within 2 %, as the app test)
  CHECK(fe->time() == Approx(0.04 * 290.0 / 350.0).epsilon(0.02));
  Eigen::MatrixXd attached;
  fe->write("top_centres", "attached", attached);
  // each eroded Hex8 took its top quad's two triangles
  CHECK((attached.array() == 0.0).count() == static_cast<Eigen::Index>(2.0 * failed));
  CHECK(((attached.array() == 0.0) || (attached.array() == 1.0)).all());

  // a DEM granule (r = 5 mm) resting on the top face of an eroded element, under gravity
  Eigen::Index gone = 0;
  while (attached(gone, 0) != 0.0) ++gone;
  const double x = 0.05 + 0.1 * std::floor(centres.mesh.points()(gone, 0) / 0.1);
  {
    std::ofstream f(dir / "one.data");
    f << "# one granule\n\n1 atoms\n1 atom types\n\n0 0.3 xlo xhi\n0 0.05 ylo yhi\n"
         "0 0.1 zlo zhi\n\nAtoms\n\n1 1 0.01 2500 "
      << x << " 0.025 0.055\n";
  }
  const std::string yaml =
      "solver: dem\n"
      "materials: {glass: {youngs_modulus: 200 MPa, poisson_ratio: 0.23, density: 2500},\n"
      "            steel: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}}\n"
      "interactions: [{pair: [glass, steel], friction: 0.3, restitution: 0.3}]\n"
      "particles: {material: glass, file: one.data}\n"
      "meshes: [{name: top, from: strip.top, material: steel}]\n"
      "gravity: [0, 0, -9.81]\nmonitor_particles: [1]\n";
  auto dem = test::make_solver("dem", yaml, dir, dir);
  REQUIRE(dem->mesh_requests().size() == 1);
  dem->receive_mesh("top", top.mesh);
  REQUIRE(test::find_mesh(*dem, "top_centres").mesh.size() == centres.mesh.size());
  const double h = 0.5 * dem->stable_time_step();
  // held while the face is intact
  const auto run = [&](const Eigen::MatrixXd& a, double time) {
    for (double t = 0.0; t < time; t += h) {
      dem->read("top_centres", "attached", a);
      dem->advance(h);
    }
  };
  run(intact, 0.02);
  const double weight = 2500 * 4.0 / 3.0 * 3.141592653589793 * 1.25e-7 * 9.81;
  CHECK(test::monitor_value(*dem, "top.force_z") == Approx(-weight).epsilon(0.02));
  CHECK(test::monitor_value(*dem, "particle.1.z") == Approx(0.055).epsilon(1e-3));
  // and falls through once the elements under it are eroded: no force on the face, and the
  // granule lies below it after 0.05 s (a free fall of 12 mm from rest)
  run(attached, 0.05);
  CHECK(test::monitor_value(*dem, "top.force_z") == 0.0);
  CHECK(test::monitor_value(*dem, "particle.1.z") < 0.05 - 0.005);
  CHECK(test::monitor_value(*dem, "kinetic_energy") ==
        Approx(0.5 * (weight / 9.81) * std::pow(9.81 * 0.05, 2)).epsilon(0.02));
  fs::remove_all(dir);
}

// Eroding contact: an interior interface (the faces between elements) is in contact only where
// erosion exposes a face. The FE writes the rule for each triangle (its element in, the one
// across eroded); a granule moving through an eroded element's hole then meets the faces of
// the elements around the hole, and without that interface passes through the steel.
TEST_CASE("eroded surface: the faces erosion exposes stop a granule inside the hole",
          "[adapters][fem][dem][rupture]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_exposed_faces_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string strip = kStrip;
  const std::string top = "interfaces: [{name: top, face: zmax}]";
  strip.replace(strip.find(top), top.size(),
                "interfaces: [{name: top, face: zmax}, {name: exposed, face: between}]");
  const std::string mesh = "cells: [3, 1, 1]}, element: hex8";
  strip.replace(strip.find(mesh), mesh.size(),
                "cells: [3, 1, 1]}, element: hex8, interior_faces: [{name: between}]");
  auto fe = test::make_solver("fem", strip, dir, dir);
  const InterfaceMesh& exposed = test::find_mesh(*fe, "exposed");
  // three Hex8 along x share two faces: four quads, eight triangles
  REQUIRE(exposed.mesh.num_triangles() == 8);
  const auto normal = [&](Eigen::Index t) {
    const auto& p = exposed.mesh.points();
    const auto tri = exposed.mesh.triangles().row(t);
    const Eigen::Vector3d a = p.row(tri(0)).transpose(), b = p.row(tri(1)).transpose(),
                          c = p.row(tri(2)).transpose();
    return Eigen::Vector3d((b - a).cross(c - a).normalized());
  };
  Eigen::MatrixXd a;
  fe->write("exposed_centres", "attached", a);
  CHECK((a.array() == 0.0).all());  // nothing eroded: nothing exposed

  // pulled to the first failure; which elements eroded, from the top face (two triangles each)
  const double dt = 0.9 * fe->stable_time_step();
  while (test::monitor_value(*fe, "failed_elements") < 1.0 && fe->time() < 0.035) fe->advance(dt);
  Eigen::MatrixXd top_attached;
  fe->write("top_centres", "attached", top_attached);
  const InterfaceMesh& top_centres = test::find_mesh(*fe, "top_centres");
  bool eroded[3] = {false, false, false};
  for (Eigen::Index t = 0; t < top_attached.rows(); ++t)
    if (top_attached(t, 0) == 0.0)
      eroded[static_cast<int>(std::floor(top_centres.mesh.points()(t, 0) / 0.1))] = true;
  REQUIRE((eroded[0] || eroded[1] || eroded[2]));
  fe->write("exposed_centres", "attached", a);
  const InterfaceMesh& centres = test::find_mesh(*fe, "exposed_centres");
  for (Eigen::Index t = 0; t < a.rows(); ++t) {
    // a face at x = 0.1 or 0.2 between elements k - 1 and k, pointing from its own element
    const double x = centres.mesh.points()(t, 0);
    const int k = static_cast<int>(std::lround(x / 0.1));
    const int own = normal(t).x() > 0.0 ? k - 1 : k, across = normal(t).x() > 0.0 ? k : k - 1;
    INFO("triangle " << t << " at x = " << x);
    CHECK(a(t, 0) == (!eroded[own] && eroded[across] ? 1.0 : 0.0));
  }

  // the DEM: the middle element eroded, a granule (r = 5 mm) in its hole moving along +x at
  // 1 m/s, no gravity: it meets the face of the element at x = 0.2 and comes back
  Eigen::MatrixXd middle(a.rows(), 1), top_middle(top_attached.rows(), 1);
  for (Eigen::Index t = 0; t < a.rows(); ++t) {
    const int k = static_cast<int>(std::lround(centres.mesh.points()(t, 0) / 0.1));
    const int own = normal(t).x() > 0.0 ? k - 1 : k;
    middle(t, 0) = own != 1 ? 1.0 : 0.0;  // rule: element 1 eroded, 0 and 2 in
  }
  for (Eigen::Index t = 0; t < top_attached.rows(); ++t)
    top_middle(t, 0) = std::floor(top_centres.mesh.points()(t, 0) / 0.1) == 1.0 ? 0.0 : 1.0;
  {
    std::ofstream f(dir / "one.data");
    f << "# one granule\n\n1 atoms\n1 atom types\n\n0 0.3 xlo xhi\n0 0.05 ylo yhi\n"
         "0 0.05 zlo zhi\n\nAtoms\n\n1 1 0.01 2500 0.15 0.025 0.025\n\nVelocities\n\n1 1 0 0 0 0 0\n";
  }
  for (const bool with_exposed : {true, false}) {
    const std::string yaml =
        "solver: dem\n"
        "materials: {glass: {youngs_modulus: 200 MPa, poisson_ratio: 0.23, density: 2500},\n"
        "            steel: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}}\n"
        "interactions: [{pair: [glass, steel], friction: 0.3, restitution: 0.5}]\n"
        "particles: {material: glass, file: one.data}\n"
        "meshes: [{name: top, from: strip.top, material: steel}" +
        std::string(with_exposed ? ", {name: exposed, from: strip.exposed, material: steel}" : "") +
        "]\nlost_margin: 1.0\nmonitor_particles: [1]\n";
    auto dem = test::make_solver("dem", yaml, dir, dir);
    for (const auto& r : dem->mesh_requests())
      dem->receive_mesh(r.name, r.name == "top" ? test::find_mesh(*fe, "top").mesh : exposed.mesh);
    const double h = 0.5 * dem->stable_time_step();
    double most_x = 0.0, peak_force = 0.0;
    for (double t = 0.0; t < 0.1; t += h) {
      dem->read("top_centres", "attached", top_middle);
      if (with_exposed) dem->read("exposed_centres", "attached", middle);
      dem->advance(h);
      most_x = std::max(most_x, test::monitor_value(*dem, "particle.1.x"));
      if (with_exposed)
        peak_force = std::max(peak_force, test::monitor_value(*dem, "exposed.force_x"));
    }
    INFO("with the exposed faces: " << with_exposed << ", largest x " << most_x);
    if (with_exposed) {
      // held in the hole: its centre within a radius of the face at x = 0.2 (Hertz overlap of a
      // 1 m/s impact on steel: well below a millimetre), and pushed back
      CHECK(most_x < 0.2 - 0.005 + 1e-3);
      CHECK(most_x > 0.2 - 0.005 - 1e-3);
      CHECK(peak_force > 0.0);
      CHECK(test::monitor_value(*dem, "particle.1.vx") < 0.0);
    } else {
      // through the steel of element 2, unhindered: 0.15 m + 1 m/s x 0.1 s
      CHECK(most_x == Approx(0.25).epsilon(1e-3));
    }
  }
  fs::remove_all(dir);
}
