// The parallel schemes with the participants of the process on threads (coupling.concurrent,
// the default) through the executable: every CSV and VTK file byte for byte that of the
// participants one after the other (the tube with IQN-ILS, implicit-parallel; the seed-000 steel
// plate and granules, explicit-parallel: FEM and DEM at the same time), with the threads shared
// (--threads 2: one OpenMP thread each on threads, two each one after the other); a participant
// that fails stops the run naming it.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kSource = PARTITA_SOURCE_DIR;

fs::path scratch(const std::string& name) { return partita::test::scratch_dir("threads", name); }

using partita::test::result_files;

// The case with `sets`, on threads and one after the other: the same files, the same bytes.
void same_bytes_on_threads(const std::string& case_file, const std::string& sets) {
  const fs::path on = scratch("on"), off = scratch("off");
  const std::string c = quote((kSource / case_file).string()) + " --threads 2 " + sets;
  auto r = partita::test::run_partita("run " + c + " --output " + quote(on.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  // the summary says the participants ran on threads, one OpenMP thread each of the 2
  CHECK(r.output.find("at the same time on threads, OpenMP threads 1, 1") != std::string::npos);
  r = partita::test::run_partita("run " + c + " --set coupling.concurrent=false --output " +
                                 quote(off.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("at the same time on threads") == std::string::npos);
  const auto a = result_files(on), b = result_files(off);
  REQUIRE(a == b);
  REQUIRE(a.size() > 3);
  for (const auto& f : a) {
    INFO("file " << f);
    CHECK(partita::test::read_file(on / f) == partita::test::read_file(off / f));
  }
  fs::remove_all(on);
  fs::remove_all(off);
}

}  // namespace

TEST_CASE("parallel schemes on threads write the bytes of the participants one after the other",
          "[app][threads]") {
  SECTION("implicit-parallel, IQN-ILS (tube)") {
    same_bytes_on_threads("cases/elastic_tube_1d/iqn-ils.yaml",
                          "--set coupling.scheme=implicit-parallel --set time.end=0.2 "
                          "--log-level info");
  }
  SECTION("explicit-parallel, FEM plate and DEM granules (seed 000, steel)") {
    same_bytes_on_threads("cases/uniaxial_compaction/steel.yaml",
                          "--set coupling.scheme=explicit-parallel --set time.end=0.0008 "
                          "--set output.every=2e-4 --log-level info");
  }
}

TEST_CASE("parallel schemes on threads share --threads N: N / k each, the first N mod k one more",
          "[app][threads]") {
  const fs::path dir = scratch("share");
  const std::string c = quote((kSource / "cases/elastic_tube_1d/iqn-ils.yaml").string()) +
                        " --set coupling.scheme=implicit-parallel --set time.end=0.03 "
                        "--log-level info --output " + quote(dir.string());
  // (--threads 2: 1, 1 above; each run also plots its CSV files, a few seconds)
  for (const auto& [threads, share] : {std::pair<int, std::string>{1, "1, 1"}, {3, "2, 1"}}) {
    const auto r = partita::test::run_partita("run " + c + " --threads " + std::to_string(threads));
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(r.output.find("on threads, OpenMP threads " + share + ":") != std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("parallel schemes on threads: a participant that fails stops the run naming it",
          "[app][threads][errors]") {
  // the tube with an explicit coupling is unstable: the fluid's Newton iteration fails
  const fs::path dir = scratch("fails");
  const auto r = partita::test::run_partita(
      "run " + quote((kSource / "tests/mpi/tube_explicit.yaml").string()) +
      " --threads 2 --set coupling.scheme=explicit-parallel --output " + quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("partita: error: participant 'fluid' failed: tube1d-fluid: tube1d flow: "
                      "Newton did not converge") != std::string::npos);
  fs::remove_all(dir);
}
