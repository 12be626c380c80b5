// A restart file of format 5 (written by partita before the services had sections of their own,
// tests/inputs/restart_format5/) still continues its run: resumed to t = 0.2 s, the tube writes
// the bytes of the same tube run straight through to 0.2 s (coupling.csv, the monitor tube.csv).
// The file is the restart point after window 5 of
//   partita run cases/elastic_tube_1d/iqn-ils.yaml --set time.end=0.05
//     --set output.restart.every_windows=5 --set participants.fluid.cells=20
//     --set participants.solid.cells=20
// (a change to that case's participants or coupling sections makes it a file of another case:
// then write it again with the last partita of format 5).

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;

TEST_CASE("restart: a file of format 5 resumes to the bytes of a run straight through",
          "[app][restart]") {
  const fs::path source = PARTITA_SOURCE_DIR;
  const fs::path dir = partita::test::scratch_dir("restart_format5", "resumed");
  const fs::path straight = partita::test::scratch_dir("restart_format5", "straight");
  fs::create_directories(dir / "restart");
  fs::copy_file(source / "tests/inputs/restart_format5/w000000000005.bin",
                dir / "restart" / "w000000000005.bin", fs::copy_options::overwrite_existing);
  const std::string args =
      "run " + quote((source / "cases/elastic_tube_1d/iqn-ils.yaml").string()) +
      " --set time.end=0.2 --set participants.fluid.cells=20 --set participants.solid.cells=20";
  auto r = partita::test::run_partita(args + " --resume " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("resumed after window 5") != std::string::npos);
  r = partita::test::run_partita(args + " --output " + quote(straight.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  for (const char* csv : {"coupling.csv", "tube.csv"}) {
    INFO(csv);
    const std::string resumed = partita::test::read_file(dir / csv);
    CHECK(resumed.size() > 100);
    CHECK(resumed == partita::test::read_file(straight / csv));
  }
  fs::remove_all(dir);
  fs::remove_all(straight);
}
