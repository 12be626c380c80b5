// The VTK files a run writes open in VTK's own XML readers (those ParaView uses): every file of
// every .pvd collection parses, has points and cells, one tuple per point or cell in each array
// and finite values (tests/support/check_vtk.py, python3-vtk9).

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;
using partita::test::run_command;

TEST_CASE("output: every VTK file of a coupled run opens in VTK's readers", "[app][output][slow]") {
  const fs::path out = fs::temp_directory_path() / "partita_test_vtk_output";
  fs::remove_all(out);
  const std::string source = PARTITA_SOURCE_DIR;
  // the seed-000 steel case, shortened, on a coarse plate: FE .vtu, particle, STL and interface
  // .vtp files with their data
  const auto run = run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote(source + "/cases/uniaxial_compaction/steel.yaml") + " --output " + quote(out.string()) +
      " --set 'participants.plate.mesh.box.cells=[6, 6, 1]' --set time.end=0.002"
      " --set output.every=0.0005 --log-level warn");
  INFO(run.output);
  REQUIRE(run.status == 0);
  const auto check =
      run_command("/usr/bin/python3 " + quote(source + "/tests/support/check_vtk.py") + " " +
                  quote(out.string()));
  INFO(check.output);
  CHECK(check.status == 0);
  CHECK(check.output.find("plate_fem.pvd: 5 files") != std::string::npos);
  CHECK(check.output.find("granules_particles.pvd: 5 files") != std::string::npos);
  fs::remove_all(out);
}
