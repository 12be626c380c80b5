// A run whose parallel scheme puts the participants of one process on threads
// (coupling.concurrent) writes the bytes of the same run with the participants one after the
// other; coupling.concurrent on a serial scheme is a clear error at the key.
//   y1' = -a1 y1 + b1 y2,  y2' = -a2 y2 + b2 y1  (ode_participant.hpp)
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "../ode_participant.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/case_run.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::run;

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() /
               ("partita_threads_test_" + std::to_string(::getpid())) / name;
  fs::create_directories(d);
  return d;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string ode_case = R"(case: ode-threads
time: {window: 0.1, end: 2.0}
participants:
  one: {solver: test-ode, writes: y1, reads: y2, a: 1.0, b: 0.5, y0: 1.0}
  two: {solver: test-ode, writes: y2, reads: y1, a: 1.5, b: 2.0}
coupling:
  scheme: SCHEME
  concurrent: CONCURRENT
  substeps: {two: 3}
  exchanges:
    - {data: y1, from: one.point, to: two.point}
    - {data: y2, from: two.point, to: one.point}
IMPLICIT
monitors:
  - {name: state, quantities: [one.y, two.y]}
output: {every: 0.5}
)";

const std::string implicit_keys = R"(  convergence:
    - {type: relative, data: y1, limit: 1.0e-9}
    - {type: relative, data: y2, limit: 1.0e-9}
  acceleration: {type: iqn-ils, initial_relaxation: 0.5})";

std::string replaced(std::string text, const std::string& what, const std::string& by) {
  text.replace(text.find(what), what.size(), by);
  return text;
}

}  // namespace

TEST_CASE("Parallel schemes on threads write the bytes of the participants one after the other",
          "[coupling][scheme][threads]") {
  const Registries r = test::test_registries();
  for (const std::string scheme : {"explicit-parallel", "implicit-parallel"}) {
    std::string text = replaced(ode_case, "SCHEME", scheme);
    text = replaced(text, "IMPLICIT", scheme == "implicit-parallel" ? implicit_keys : "");
    std::vector<std::string> files[2];
    for (const bool concurrent : {true, false}) {
      const fs::path dir = scratch(scheme + (concurrent ? "_threads" : "_one_by_one"));
      const fs::path file = dir / "case.yaml";
      std::ofstream(file) << replaced(text, "CONCURRENT", concurrent ? "true" : "false");
      RunOptions o;
      o.output_dir = dir / "out";
      CaseRun run(file, r, o);
      run.run();
      INFO(scheme << (concurrent ? " on threads" : " one by one"));
      CHECK(run.summary().windows == 20);
      // threads only where asked: one OpenMP share per participant, none one by one
      CHECK(run.scheme().concurrent_omp_threads().size() == (concurrent ? 2u : 0u));
      CHECK(run.summary().overlap_seconds >= 0.0);
      for (const char* f : {"coupling.csv", "state.csv"})
        files[concurrent ? 0 : 1].push_back(read_bytes(o.output_dir / f));
    }
    INFO(scheme);
    REQUIRE(files[0].size() == 2);
    CHECK(files[0][0].size() > 100);  // a header and 20 rows
    CHECK(files[0][0] == files[1][0]);  // coupling.csv
    CHECK(files[0][1] == files[1][1]);  // state.csv (the monitors)
  }
}

TEST_CASE("coupling.concurrent on a serial scheme is a clear error at the key",
          "[coupling][case][errors]") {
  const Registries r = test::test_registries();
  std::string text = replaced(ode_case, "SCHEME", "explicit-serial");
  text = replaced(replaced(text, "IMPLICIT", ""), "CONCURRENT", "true");
  const fs::path dir = scratch("serial_concurrent");
  std::ofstream(dir / "case.yaml") << text;
  RunOptions o;
  o.output_dir = dir / "out";
  o.check_only = true;
  try {
    CaseRun run(dir / "case.yaml", r, o);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("coupling.concurrent") &&
                                          Catch::Contains("explicit-serial") &&
                                          Catch::Contains("explicit-parallel and implicit-parallel"));
  }
  // false is harmless on a serial scheme (one after the other is what it does)
  std::ofstream(dir / "case.yaml") << replaced(text, "concurrent: true", "concurrent: false");
  CHECK_NOTHROW(CaseRun(dir / "case.yaml", r, o));
}
