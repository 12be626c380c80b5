// An FE face handed to the DEM as a contact surface (meshes: [{from: block.top}]): granules
// settle onto it inside frictionless DEM side walls (tests/inputs/handover/fe_floor.yaml). At
// rest the FE face carries the granules' whole weight m g (static equilibrium; the side walls
// take no vertical force without friction), within 0.5 %; the force the FE side receives equals
// the force the DEM's particles put on the surface (a conservative exchange), and the horizontal
// forces on floor and side walls cancel within 0.5 % of the weight.

#include <catch2/catch.hpp>

#include "../support/monitor_csv.hpp"
#include "../support/run_command.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

TEST_CASE("mesh hand-over: granules at rest on an FE face load it with their weight",
          "[app][handover][slow]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_floor_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/handover/fe_floor.yaml").string()) +
      " --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto csv = partita::test::MonitorCsv::read(dir / "forces.csv");
  REQUIRE(csv.rows.size() > 100);
  auto mean = csv.mean_over_last(0.1);  // the bed at rest
  const double weight = mean["granules.mass"] * 9.81;
  REQUIRE(weight > 0.0);
  INFO("weight " << weight << " N, FE face " << mean["block.top.force_z"] << " N, DEM "
                 << mean["granules.floor.force_z"] << " N");
  CHECK(mean["granules.kinetic_energy"] < 1e-4 * weight * 0.01);  // at rest: E_k << m g (1 cm)
  CHECK(-mean["block.top.force_z"] == Approx(weight).epsilon(0.005));
  CHECK(mean["block.top.force_z"] == Approx(mean["granules.floor.force_z"]).epsilon(0.005));
  CHECK(std::abs(mean["granules.floor.force_x"] + mean["granules.sides.force_x"]) < 0.005 * weight);
  CHECK(std::abs(mean["granules.floor.force_y"] + mean["granules.sides.force_y"]) < 0.005 * weight);
  fs::remove_all(dir);
}

// A rigid indenter's surface handed to the DEM (tests/inputs/handover/indenter_in_bed.yaml): the
// FE participant's driven sphere (held 5 ms, then 0.2 m/s down) is the DEM mesh `ball`, moved by
// the exchanged displacement. It ends where its velocity table puts it (z = 0.011 - 0.2 x
// 0.024995 m), untouched by granules while it hangs above the bed, and the granules push it up
// once it sinks into them.
TEST_CASE("mesh hand-over: a rigid indenter's sphere sinks into a granular bed",
          "[app][handover][contact]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_bed_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/handover/indenter_in_bed.yaml").string()) +
      " --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto csv = partita::test::MonitorCsv::read(dir / "ball.csv");
  REQUIRE(csv.rows.size() == 301);  // t = 0 and 300 windows
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < csv.header.size(); ++c) col[csv.header[c]] = c;
  CHECK(csv.rows.back()[col.at("block.ball.z")] == Approx(0.011 - 0.2 * 0.024995).epsilon(1e-9));
  CHECK(csv.rows[40][col.at("granules.ball.force_z")] == 0.0);  // t = 4 ms: above the bed
  const auto mean = csv.mean_over_last(0.3);
  CHECK(mean.at("granules.ball.force_z") > 0.0);  // the bed resists
  CHECK(fs::exists(dir / "vtk" / "block_ball.pvd"));  // the indenter's surface, frame by frame
  fs::remove_all(dir);
}
