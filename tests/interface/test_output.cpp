// Output files: atomic replacement, CSV series, ParaView collections and the clean-up of an
// earlier run's VTK series.

#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace partita;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("partita_test_output_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void touch(const fs::path& p, const std::string& text = "x") {
  std::ofstream(p) << text;
}

}  // namespace

TEST_CASE("output: an AtomicFile that is not committed leaves the old file in place",
          "[interface][output]") {
  const fs::path dir = scratch("atomic");
  const fs::path file = dir / "result.csv";
  write_file_atomically(file, "good\n");
  {
    AtomicFile f(file);
    f.stream() << "half-writ";
    // destroyed without commit(), as when an exception unwinds the writer
  }
  CHECK(read(file) == "good\n");
  CHECK_FALSE(fs::exists(dir / "result.csv.part"));
  {
    AtomicFile f(file);
    f.stream() << "new\n";
    f.commit();
  }
  CHECK(read(file) == "new\n");
  CHECK_THROWS_AS(AtomicFile(dir / "result.csv" / "inside_a_file"), Error);
}

TEST_CASE("output: a CSV series has a header with units and only complete rows on disk",
          "[interface][output]") {
  const fs::path dir = scratch("csv");
  const fs::path file = dir / "reaction.csv";
  CsvSeries csv(file, "time", "s", {{"force_z", "N"}, {"iterations", ""}});
  // nothing on disk before the first flush (a resumed run replaces the text first: a file of
  // the run it continues stays untouched until the restart file is accepted)
  CHECK_FALSE(fs::exists(file));
  csv.flush();
  CHECK(read(file) == "time [s],force_z [N],iterations\n");
  csv.record(0.5, {4.0, 2.0});
  CHECK(read(file) == "time [s],force_z [N],iterations\n");  // not flushed yet
  csv.flush();
  csv.record(1.0, {4.25, 3.0});
  csv.close();
  CHECK(read(file) == "time [s],force_z [N],iterations\n0.5,4,2\n1,4.25,3\n");
  CHECK_FALSE(fs::exists(dir / "reaction.csv.part"));
  CsvSeries other(dir / "other.csv", "time", "s", {{"a", ""}});
  CHECK_THROWS_WITH(other.record(0.0, {1.0, 2.0}), Catch::Contains("2 values, the header 1"));
}

TEST_CASE("output: a new run removes the VTK series of an earlier run and nothing else",
          "[interface][output]") {
  const fs::path dir = scratch("pvd");
  const fs::path vtk = dir / "vtk";
  fs::create_directories(vtk);
  {
    PvdSeries series(vtk / "granules_particles.pvd");
    for (int k = 0; k < 5; ++k) {
      const std::string name = "granules_particles_00000" + std::to_string(k) + ".vtp";
      touch(vtk / name);
      series.add(1e-3 * k, name);
    }
  }
  CHECK(read(vtk / "granules_particles.pvd").find("timestep=\"0.004\"") != std::string::npos);
  // a hand-edited collection pointing outside the folder, and files the user put there
  write_file_atomically(vtk / "odd.pvd",
                        "<VTKFile><Collection><DataSet file=\"../keep.vtp\"/>"
                        "<DataSet file=\"/tmp/absolute.vtp\"/></Collection></VTKFile>\n");
  touch(dir / "keep.vtp");
  touch(vtk / "notes.txt");
  touch(vtk / "unlisted.vtp");
  CHECK(remove_pvd_series(vtk) == 5 + 1 + 1);  // five frames and the two collections
  CHECK(fs::exists(dir / "keep.vtp"));
  CHECK(fs::exists(vtk / "notes.txt"));
  CHECK(fs::exists(vtk / "unlisted.vtp"));
  CHECK_FALSE(fs::exists(vtk / "granules_particles_000003.vtp"));
  CHECK_FALSE(fs::exists(vtk / "granules_particles.pvd"));
  CHECK(remove_pvd_series(vtk) == 0);
  CHECK(remove_pvd_series(dir / "missing") == 0);
}
