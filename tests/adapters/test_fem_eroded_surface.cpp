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
