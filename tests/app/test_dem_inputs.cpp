// DEM inputs through the executable: an STL whose orientation contradicts itself is
// accepted with a warning naming the triangles; the set-up log counts meshes handed over.
#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;

TEST_CASE("dem inputs: an STL of contradicting orientation is accepted with a warning",
          "[app][dem-inputs]") {
  const fs::path c = fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/dem_orientation/case.yaml";
  const auto r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " check " +
                                            quote(c.string()));
  INFO(r.output);
  CHECK(r.status == 0);
  // the stored normal of the second facet contradicts its vertex order, and the two triangles'
  // windings disagree over their shared edge: both said, with the triangles and lines
  CHECK(r.output.find("flipped.stl: 1 of 2 facets have a stored normal that points against") !=
        std::string::npos);
  CHECK(r.output.find("1 edges are shared by neighbours whose vertex orders disagree") !=
        std::string::npos);
  CHECK(r.output.find("triangle 0 (facet at line 2) and triangle 1 (facet at line 9)") !=
        std::string::npos);
  CHECK(r.output.find("two-sided") != std::string::npos);  // what the DEM does with it
}

TEST_CASE("dem inputs: the set-up log counts a mesh handed over by another participant",
          "[app][dem-inputs]") {
  const fs::path c = fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/handover/fe_floor.yaml";
  const auto r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " check " +
                                            quote(c.string()) + " --log-level info");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("1 walls, 1 meshes (1 handed over by other participants)") !=
        std::string::npos);
  CHECK(r.output.find(" 0 meshes") == std::string::npos);
}

TEST_CASE("dem inputs: partita docs dem documents the wall faces and particle monitors",
          "[app][dem-inputs]") {
  const auto r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " docs dem");
  INFO(r.output);
  REQUIRE(r.status == 0);
  // a box wall's force is documented as what it is (not "on a plane wall")
  CHECK(r.output.find("on a plane wall") == std::string::npos);
  CHECK(r.output.find("a plane, or all faces of a box") != std::string::npos);
  for (const char* q : {"<wall>.<face>.force_z", "particle.<id>.z", "particle.<id>.vz",
                        "monitor_particles", "lost_margin"})
    CHECK(r.output.find(q) != std::string::npos);
}
