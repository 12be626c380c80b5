// CaseRun: a whole case from YAML (with the test-local solver "test-ode"), its output files and
// its errors.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "../ode_participant.hpp"
#include "partita/run/case_run.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::run;

namespace {

// Options by name (robust to fields added later).
RunOptions run_options(const std::filesystem::path& dir, bool check_only) {
  RunOptions o;
  o.output_dir = dir;
  o.check_only = check_only;
  return o;
}

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("partita_coupling_test_" + std::to_string(::getpid())) / name;
  fs::create_directories(d);
  return d;
}

fs::path write_case(const std::string& name, const std::string& text) {
  fs::path p = scratch("cases") / (name + ".yaml");
  std::ofstream(p) << text;
  return p;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string participants = R"(
participants:
  one: {solver: test-ode, writes: y1, reads: y2, a: 1.0, b: 0.5, y0: 1.0}
  two: {solver: test-ode, writes: y2, reads: y1, a: 1.5, b: 2.0}
)";

const std::string exchanges = R"(
  exchanges:
    - {data: y1, from: one.point, to: two.point}
    - {data: y2, from: two.point, to: one.point}
)";

std::string implicit_case(
    const std::string& acceleration = "{type: iqn-ils, initial_relaxation: 0.5}") {
  return "case: ode\ntime: {window: 0.1, end: 1.0}\n" + participants +
         "coupling:\n  scheme: implicit-serial\n" + exchanges +
         "  convergence:\n    - {type: relative, data: y1, limit: 1.0e-8}\n"
         "    - {type: absolute, data: y2, limit: 1.0e-9}\n"
         "  acceleration: " +
         acceleration +
         "\n"
         "monitors:\n  - {name: state, quantities: [one.y, two.y]}\n"
         "output: {every: 0.5}\n";
}

std::string error_of(const std::string& name, const std::string& text) {
  const Registries r = test::test_registries();
  try {
    CaseRun run(write_case(name, text), r, run_options(scratch("out_" + name), true));
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("CaseRun runs a YAML case and writes coupling.csv, monitors and VTK series",
          "[coupling][case]") {
  const Registries r = test::test_registries();
  const fs::path out = scratch("run_ok");
  CaseRun run(write_case("ok", implicit_case()), r, run_options(out, false));
  CHECK(run.window_count() == 10);
  run.run();
  const std::string csv = read_text(out / "coupling.csv");
  CHECK(csv.rfind("window,time [s],iterations,relative y1,absolute y2 [m]\n", 0) == 0);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 11);
  const std::string mon = read_text(out / "state.csv");
  CHECK(mon.rfind("time [s],one.y [m],two.y [m]\n", 0) == 0);
  CHECK(std::count(mon.begin(), mon.end(), '\n') == 12);  // header, t = 0, 10 windows
  CHECK(fs::exists(out / "vtk" / "one_interface_point.pvd"));
  CHECK(fs::exists(out / "vtk" / "one_interface_point_000002.vtp"));  // frames at 0, 0.5, 1.0
  CHECK(run.summary().windows == 10);
  CHECK(run.summary().mean_iterations() > 1.0);
  CHECK(run.summary().mean_iterations() < 10.0);
  CHECK(run.summary().unconverged_windows == 0);
}

TEST_CASE("CaseRun check_only builds everything and writes nothing", "[coupling][case]") {
  const Registries r = test::test_registries();
  const fs::path out = scratch("check_only") / "never";
  CaseRun run(write_case("check", implicit_case()), r, run_options(out, true));
  run.run();
  CHECK_FALSE(fs::exists(out));
  CHECK(run.scheme().name() == "implicit-serial");
}

TEST_CASE("CaseRun: bad coupling settings are clear errors at the key",
          "[coupling][case][errors]") {
  SECTION("unknown acceleration names the key and the nearest name") {
    const std::string e = error_of("acc", implicit_case("{type: iqn-il}"));
    CHECK_THAT(e, Catch::Contains("coupling.acceleration.type") &&
                      Catch::Contains("unknown acceleration 'iqn-il'") &&
                      Catch::Contains("did you mean 'iqn-ils'"));
    CHECK_THAT(e, Catch::Contains("acc.yaml:"));
  }
  SECTION("implicit scheme without convergence measure") {
    const std::string text = "case: x\ntime: {window: 0.1, end: 1.0}\n" + participants +
                             "coupling:\n  scheme: implicit-parallel\n" + exchanges;
    const std::string e = error_of("noconv", text);
    CHECK_THAT(e, Catch::Contains("key 'coupling'") && Catch::Contains("convergence"));
  }
  SECTION("window <= 0") {
    const std::string text = "case: x\ntime: {window: 0, end: 1.0}\n" + participants +
                             "coupling:\n  scheme: explicit-serial\n" + exchanges;
    const std::string e = error_of("window", text);
    CHECK_THAT(e, Catch::Contains("time.window") && Catch::Contains("0 < value"));
  }
  SECTION("unknown scheme") {
    const std::string text = "case: x\ntime: {window: 0.1, end: 1.0}\n" + participants +
                             "coupling:\n  scheme: explicit-serail\n" + exchanges;
    const std::string e = error_of("scheme", text);
    CHECK_THAT(
        e, Catch::Contains("coupling.scheme") && Catch::Contains("did you mean 'explicit-serial'"));
  }
  SECTION("unknown convergence measure") {
    std::string text = implicit_case();
    text.replace(text.find("type: absolute"), 14, "type: absolut");
    const std::string e = error_of("measure", text);
    CHECK_THAT(e, Catch::Contains("coupling.convergence[1].type") &&
                      Catch::Contains("did you mean 'absolute'"));
  }
  SECTION("exchange naming a missing participant, mesh or data") {
    std::string t1 = implicit_case();
    t1.replace(t1.find("from: one.point"), 15, "from: onr.point");
    CHECK_THAT(error_of("p", t1), Catch::Contains("coupling.exchanges[0].from") &&
                                      Catch::Contains("unknown participant 'onr'") &&
                                      Catch::Contains("'one'"));
    std::string t2 = implicit_case();
    t2.replace(t2.find("to: two.point"), 13, "to: two.poin");
    CHECK_THAT(error_of("m", t2), Catch::Contains("exchanges[0].to") &&
                                      Catch::Contains("no mesh 'poin'") &&
                                      Catch::Contains("did you mean 'point'"));
    std::string t3 = implicit_case();
    t3.replace(t3.find("{data: y1"), 9, "{data: y2");
    CHECK_THAT(error_of("d", t3), Catch::Contains("exchanges[0].data") &&
                                      Catch::Contains("'one' does not write 'y2'") &&
                                      Catch::Contains("writes: y1"));
  }
  SECTION("substeps < 1") {
    const std::string text = "case: x\ntime: {window: 0.1, end: 1.0}\n" + participants +
                             "coupling:\n  scheme: explicit-serial\n  substeps: {two: 0}\n" +
                             exchanges;
    CHECK_THAT(error_of("sub", text),
               Catch::Contains("coupling.substeps.two") && Catch::Contains(">= 1"));
  }
  SECTION("map_on names the sides it allows") {
    std::string text = implicit_case();
    text.replace(text.find("{data: y1"), 9, "{map_on: middle, data: y1");
    CHECK_THAT(error_of("map_on", text), Catch::Contains("coupling.exchanges[0].map_on") &&
                                             Catch::Contains("receiver") &&
                                             Catch::Contains("sender"));
  }
  SECTION("convergence keys on an explicit scheme") {
    std::string text = implicit_case();
    text.replace(text.find("implicit-serial"), 15, "explicit-serial");
    CHECK_THAT(error_of("expl", text),
               Catch::Contains("coupling.convergence") && Catch::Contains("implicit-serial"));
  }
}

TEST_CASE("CaseRun: map_on sender and receiver give the same bytes in one process",
          "[coupling][case][map_on]") {
  // In one process the core maps every exchange, with the same mapper on the same values,
  // whichever side is named: coupling.csv and the monitors are the same bytes.
  const Registries r = test::test_registries();
  std::string sender = implicit_case();
  for (const char* data : {"{data: y1", "{data: y2"})
    sender.replace(sender.find(data), 9, std::string("{map_on: sender, ") + (data + 1));
  REQUIRE(sender.find("map_on: sender, data: y2") != std::string::npos);
  const fs::path a = scratch("map_on_receiver"), b = scratch("map_on_sender");
  CaseRun(write_case("map_receiver", implicit_case()), r, run_options(a, false)).run();
  CaseRun(write_case("map_sender", sender), r, run_options(b, false)).run();
  CHECK(read_text(a / "coupling.csv").size() > 100);
  CHECK(read_text(a / "coupling.csv") == read_text(b / "coupling.csv"));
  CHECK(read_text(a / "state.csv") == read_text(b / "state.csv"));
}

TEST_CASE("CaseRun: substeps auto follow the solver's stable time step", "[coupling][case]") {
  const Registries r = test::test_registries();
  std::string text = implicit_case();
  text.replace(text.find("reads: y1, a: 1.5"), 17, "reads: y1, stable_dt: 0.03, a: 1.5");
  text.replace(text.find("  exchanges:"), 0, "  substeps: {two: auto}\n");
  CaseRun run(write_case("auto", text), r, run_options(scratch("auto_out"), true));
  CHECK(run.participant("two")->substeps(0.1) == 4);  // ceil(0.1 / 0.03)
  CHECK(run.participant("one")->substeps(0.1) == 1);
}
