// A DEM run writes its final state as a particle file (output: {particles_file: end}) that
// another case reads (particles: {file: ...}): the restarted run's particles, written again
// before its first step, are the same file apart from the title line. The writer prints every
// number in its shortest exact form (tests/solvers/dem/test_lammps_data_io.cpp), so equal text means
// the same positions, velocities, diameters and densities bit for bit.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

// The file without its first line (the title, which names the time).
std::string body(const fs::path& f) {
  std::ifstream in(f);
  std::string title;
  std::getline(in, title);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("particle file: a settled run's final state restarts the same particles bit for bit",
          "[app][particles-file][slow]") {
  const fs::path inputs = fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/particles_file";
  const fs::path dir = fs::temp_directory_path() / ("partita_settle_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " run " +
                                      quote((inputs / "settle.yaml").string()) + " --output " +
                                      quote((dir / "settle").string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const fs::path settled = dir / "settle" / "granules.data";
  REQUIRE(fs::exists(settled));
  CHECK(!fs::exists(settled.string() + ".tmp"));
  r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " run " +
                                 quote((inputs / "restart.yaml").string()) + " --output " +
                                 quote((dir / "restart").string()) + " --set " +
                                 quote("participants.granules.particles.file=" + settled.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const fs::path again = dir / "restart" / "particles" / "granules_000000.data";
  REQUIRE(fs::exists(again));
  const std::string a = body(settled), b = body(again);
  CHECK(a.size() > 1000);
  CHECK(a.find("Velocities") != std::string::npos);
  CHECK(a == b);
  // the later frames and the end of the restarted run are written too
  CHECK(fs::exists(dir / "restart" / "particles" / "granules_000002.data"));
  CHECK(fs::exists(dir / "restart" / "granules.data"));

  // The file's densities set the masses: read with a material of another density (1000), the
  // particles keep the file's 2500 kg/m^3 (written back as mass / volume).
  r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " + quote((inputs / "restart.yaml").string()) +
      " --output " + quote((dir / "density").string()) + " --set " +
      quote("participants.granules.particles.file=" + settled.string()) + " --set " +
      quote("participants.granules.materials.glass.density=1000"));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / "density" / "particles" / "granules_000000.data");
  std::string line;
  bool atoms = false;
  int count = 0;
  while (std::getline(in, line)) {
    if (line.rfind("Atoms", 0) == 0) atoms = true;
    if (line.rfind("Velocities", 0) == 0) break;
    std::istringstream row(line);
    double id = 0, type = 0, diameter = 0, density = 0;
    if (!atoms || !(row >> id >> type >> diameter >> density)) continue;
    CHECK(density == Approx(2500.0).epsilon(1e-14));
    ++count;
  }
  CHECK(count > 50);
  fs::remove_all(dir);
}
