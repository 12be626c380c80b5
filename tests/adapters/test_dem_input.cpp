// The DEM participant's inputs: one sphere on a plane runs with the defaults, per-face box wall
// forces and particle monitors, absurd particle positions in a particle file or a restart file.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "dem_adapter_support.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using partita::test::monitor;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::path(PARTITA_BINARY_DIR) / "test_output" / "dem_input" / name;
  fs::create_directories(d);
  return d;
}

void write_file(const fs::path& f, const std::string& text) {
  std::ofstream out(f);
  out << text;
}

// A 2 cm steel ball on a granite plane: no interaction of steel with itself, no lost_margin.
std::string ball_yaml(const std::string& particles, const std::string& extra = "") {
  return "solver: dem\n"
         "materials: {steel: {youngs_modulus: 200 GPa, poisson_ratio: 0.3, density: 7800},\n"
         "            granite: {youngs_modulus: 50 GPa, poisson_ratio: 0.25, density: 2700}}\n"
         "interactions: [{pair: [steel, granite], friction: 0.3, restitution: 0.5}]\n"
         "particles: {material: steel, file: " +
         particles +
         "}\n"
         "walls: [{name: floor, plane: {point: [0, 0, 0], normal: [0, 0, 1]}, material: granite}]\n" +
         extra;
}

}  // namespace

TEST_CASE("dem participant: one sphere on a plane runs with the defaults",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("ball");
  // dropped from 5 cm (bottom 4 cm above the plane), id 7
  write_file(dir / "ball.data", "one ball\n\n1 atoms\n1 atom types\n\nAtoms\n\n7 1 0.02 7800 0 0 0.05\n");
  auto s = test::make_dem(ball_yaml("ball.data", "monitor_particles: [7]\n"), dir, dir);
  // the monitor is the particle's position
  CHECK(monitor(*s, "particle.7.z") == 0.05);
  CHECK(monitor(*s, "particle.7.vz") == 0.0);
  // the whole drop and the first rebound: never lost (the domain spans the plane's point and
  // the ball; the margin is at least five diameters)
  const double dt = s->stable_time_step();
  double lowest = 1.0;
  while (s->time() < 0.2) {
    for (int k = 0; k < 100; ++k) s->advance(dt);
    INFO("t = " << s->time());
    REQUIRE(s->check_state().empty());
    lowest = std::min(lowest, monitor(*s, "particle.7.z"));
  }
  CHECK(lowest < 0.0101);  // it reached the plane (bottom at 1 mm and less)
  CHECK(lowest > 0.0099);  // and did not pass through it

  // a ball that does fly off is lost, and the message names the key to change
  write_file(dir / "shot.data",
             "one ball\n\n1 atoms\n1 atom types\n\nAtoms\n\n1 1 0.02 7800 0 0 0.05\n\n"
             "Velocities\n\n1 0 0 100 0 0 0\n");
  auto shot = test::make_dem(ball_yaml("shot.data", "gravity: [0, 0, 0]\n"), dir, dir);
  for (int k = 0; k < 20000 && shot->check_state().empty(); ++k)
    shot->advance(shot->stable_time_step());
  const std::string lost = shot->check_state();
  INFO(lost);
  CHECK(lost.find("particle 1 is lost") != std::string::npos);
  CHECK(lost.find("lost_margin") != std::string::npos);
  CHECK(lost.find("raise the participant's key lost_margin") != std::string::npos);
}

TEST_CASE("dem participant: a particle monitor follows its id, and an unknown id is refused",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("monitor");
  auto s = test::make_dem(test::small_bed_yaml("monitor_particles: [0, 5]\nsort_interval: 1\n"),
                          dir);
  const double dt = s->stable_time_step();
  for (int k = 0; k < 300; ++k) s->advance(dt);  // renumbered in cell order on the way
  for (const auto& m : s->monitors()) {
    if (m.name.rfind("particle.", 0) != 0) continue;
    CHECK((m.unit == "m" || m.unit == "m/s"));
  }
  // the values are those of the particle with that id, wherever it is stored now
  // (kinetic energy of particle 5 alone from its monitored velocity is below the bed's)
  const double vx = monitor(*s, "particle.5.vx"), vy = monitor(*s, "particle.5.vy"),
               vz = monitor(*s, "particle.5.vz");
  CHECK(std::isfinite(vx + vy + vz));
  const double z = monitor(*s, "particle.0.z");
  CHECK(z > 0.0);
  CHECK(z < 0.0102);  // inside the box, under the plate
  CHECK_THROWS_WITH(
      test::make_dem(test::small_bed_yaml("monitor_particles: [100000]\n"), dir),
      Catch::Contains("no particle has the id 100000"));
}

TEST_CASE("dem participant: each closed face of a box wall reports its force",
          "[adapters][dem][robustness][walls]") {
  const fs::path dir = scratch("faces");
  auto s = test::make_dem(test::small_bed_yaml(), dir);
  const double dt = s->stable_time_step();
  for (int k = 0; k < 2000; ++k) s->advance(dt);
  const char* faces[] = {"xmin", "xmax", "ymin", "ymax", "zmin"};
  for (const char* axis : {"x", "y", "z"}) {
    double sum = 0.0;
    for (const char* f : faces) sum += monitor(*s, std::string("wall0.") + f + ".force_" + axis);
    CHECK(sum == Approx(monitor(*s, std::string("wall0.force_") + axis)).margin(1e-12));
  }
  CHECK(monitor(*s, "wall0.zmin.force_z") < 0.0);  // the bed presses on the floor
  for (const auto& m : s->monitors()) CHECK(m.name.find("wall0.zmax.") == std::string::npos);
}

TEST_CASE("dem participant: a particle absurdly far from the walls is refused at set-up",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("absurd");
  // a 2 cm box holding two beads, and one bead 880 m away (written in mm, read as m)
  write_file(dir / "beads.data",
             "beads\n\n3 atoms\n1 atom types\n\nAtoms\n\n1 1 0.002 2500 0.005 0.005 0.005\n"
             "2 1 0.002 2500 0.01 0.01 0.005\n3 1 0.002 2500 880 5 5\n");
  const std::string yaml =
      "solver: dem\n"
      "materials: {glass: {youngs_modulus: 1 GPa, poisson_ratio: 0.25, density: 2500}}\n"
      "interactions: [{pair: [glass, glass]}]\n"
      "particles: {material: glass, file: beads.data}\n"
      "walls: [{box: {origin: [0, 0, 0], size: [0.02, 0.02, 0.02]}, material: glass}]\n";
  try {
    (void)test::make_dem(yaml, dir, dir);
    FAIL("a bead 880 m from a 2 cm box was accepted");
  } catch (const Error& e) {
    const std::string m = e.what();
    INFO(m);
    CHECK(m.find("particle id 3 (index 2) at (880, 5, 5) m") != std::string::npos);
    CHECK(m.find("domain of the walls and meshes [0 0 0] .. [0.02 0.02 0.02] m") !=
          std::string::npos);
    CHECK(m.find("units") != std::string::npos);
  }
}

TEST_CASE("dem participant: a restart file with absurd positions is refused naming the particle",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("restart");
  write_file(dir / "good.data",
             "beads\n\n2 atoms\n1 atom types\n\nAtoms\n\n1 1 0.002 2500 0 0 0.001\n"
             "2 1 0.002 2500 0.005 0 0.001\n");
  // the same two beads with the second at 1e300 m (an exponent flipped in a file)
  write_file(dir / "bad.data",
             "beads\n\n2 atoms\n1 atom types\n\nAtoms\n\n1 1 0.002 2500 0 0 0.001\n"
             "2 1 0.002 2500 1e300 0 0.001\n");
  auto yaml = [](const std::string& file) {
    return "solver: dem\n"
           "materials: {glass: {youngs_modulus: 1 GPa, poisson_ratio: 0.25, density: 2500}}\n"
           "interactions: [{pair: [glass, glass]}]\n"
           "particles: {material: glass, file: " +
           file +
           "}\n"
           "walls: [{plane: {point: [0, 0, 0], normal: [0, 0, 1]}, material: glass}]\n";
  };
  auto bad = test::make_dem(yaml("bad.data"), dir, dir);
  std::stringstream file;
  BinaryWriter w(file);
  bad->write_restart(w);
  REQUIRE(w.good());
  auto good = test::make_dem(yaml("good.data"), dir, dir);
  BinaryReader r(file, "run.restart");
  try {
    good->read_restart(r);
    FAIL("a restart state with a particle at 1e300 m was accepted");
  } catch (const Error& e) {
    const std::string m = e.what();
    INFO(m);
    CHECK(m.find("run.restart") != std::string::npos);
    CHECK(m.find("particle id 2 (index 1) at (1e+300, 0, 0.001) m") != std::string::npos);
    CHECK(m.find("outside the domain") != std::string::npos);
    CHECK(m.find("std::") == std::string::npos);
  }
}

TEST_CASE("dem participant: two particles of one material need its self-interaction",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("pairs");
  write_file(dir / "two.data",
             "two balls\n\n2 atoms\n1 atom types\n\nAtoms\n\n1 1 0.02 7800 0 0 0.05\n"
             "2 1 0.02 7800 0.1 0 0.05\n");
  CHECK_THROWS_WITH(test::make_dem(ball_yaml("two.data"), dir, dir),
                    Catch::Contains("no interaction between materials 'steel' and 'steel', which "
                                    "can touch: the 2 particles are of material 'steel'"));
}

TEST_CASE("dem participant: a packing generated in several boxes fills each to the porosity",
          "[adapters][dem][robustness]") {
  const fs::path dir = scratch("boxes");
  // two disjoint 1 cm cells 5 mm apart (the cells of a cellular structure) and one box holding
  // the first: each box holds about (1 - n) V / V_grain
  // granules, and the two boxes get different packings (seeds seed and seed + 1)
  auto yaml = [](const std::string& generate) {
    return "solver: dem\n"
           "materials: {glass: {youngs_modulus: 200 MPa, poisson_ratio: 0.23, density: 400},\n"
           "            steel: {youngs_modulus: 250 GPa, poisson_ratio: 0.3, density: 7850}}\n"
           "interactions: [{pair: [glass, glass]}, {pair: [glass, steel]}]\n"
           "particles: {material: glass, generate: {" +
           generate +
           ", diameters: [2 mm], porosity: 0.6, seed: 3}}\n"
           "walls: [{plane: {point: [0, 0, 0], normal: [0, 0, 1]}, material: steel}]\n"
           "monitor_particles: [0]\n";
  };
  auto two = test::make_dem(
      yaml("boxes: [{origin: [0, 0, 0], size: [0.01, 0.01, 0.01]}, "
           "{origin: [0.015, 0, 0], size: [0.01, 0.01, 0.01]}]"),
      dir, dir);
  auto one = test::make_dem(yaml("box: {origin: [0, 0, 0], size: [0.01, 0.01, 0.01]}"), dir, dir);
  const double n_two = monitor(*two, "particles"), n_one = monitor(*one, "particles");
  const double expected = 0.4 * 1e-6 / (std::numbers::pi / 6.0 * 8e-9);  // 47.7 per box
  CHECK(n_one == Approx(expected).epsilon(0.05));
  CHECK(n_two == Approx(2.0 * expected).epsilon(0.05));
  // the first box is generated as the single box is (same seed): the same first granule
  CHECK(monitor(*two, "particle.0.x") == monitor(*one, "particle.0.x"));
  // mass: every granule has the same size, so the mass is the count times one granule's
  CHECK(monitor(*two, "mass") == Approx(n_two * 400.0 * std::numbers::pi / 6.0 * 8e-9));
  // box and boxes together are refused
  CHECK_THROWS_WITH(
      test::make_dem(yaml("box: {origin: [0, 0, 0], size: [0.01, 0.01, 0.01]}, boxes: []"), dir,
                     dir),
      Catch::Contains("boxes"));
}
