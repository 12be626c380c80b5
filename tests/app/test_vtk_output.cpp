// The VTK files a run writes open in VTK's own XML readers (those ParaView uses): every file of
// every .pvd collection parses, has points and cells, one tuple per point or cell in each array
// and finite values (tests/support/check_vtk.py, python3-vtk9); the same run in every format of
// output.vtk writes the same values (tests/support/vtk_arrays.py).

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/vtk_read.hpp"

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

TEST_CASE("output: every output.vtk format of a run holds the same values",
          "[app][output][vtk][slow]") {
  const fs::path out = fs::temp_directory_path() / "partita_test_vtk_formats";
  fs::remove_all(out);
  const std::string source = PARTITA_SOURCE_DIR;
  for (const char* format : {"zlib", "binary", "ascii"}) {
    const auto run = run_command(
        quote(PARTITA_EXECUTABLE) + " run " +
        quote(source + "/cases/uniaxial_compaction/steel.yaml") + " --output " +
        quote((out / format).string()) +
        " --set 'participants.plate.mesh.box.cells=[6, 6, 1]' --set time.end=0.001"
        " --set output.every=0.0005 --set output.vtk.precision=float64 --set output.vtk.format=" +
        format + " --log-level warn");
    INFO(run.output);
    REQUIRE(run.status == 0);
    const auto check =
        run_command("/usr/bin/python3 " + quote(source + "/tests/support/check_vtk.py") + " " +
                    quote((out / format).string()));
    INFO(check.output);
    CHECK(check.status == 0);
  }
  int files = 0;
  for (const auto& e : fs::directory_iterator(out / "zlib" / "vtk")) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".pvd") continue;
    INFO(name);
    const auto z = partita::test::read_vtk(e.path());
    REQUIRE(z.ok);
    CHECK(partita::test::read_vtk(out / "binary" / "vtk" / name).text == z.text);
    CHECK(partita::test::read_vtk(out / "ascii" / "vtk" / name).text == z.text);
    ++files;
  }
  CHECK(files == 7 * 3);  // FE plate, particles, STL plate, four interface meshes; 3 frames
  fs::remove_all(out);
}
