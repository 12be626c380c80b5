// The DEM adapter's breakage keys: validation (ranges, pattern names with "did you mean"),
// monitors, the stable step that falls as fragments appear, a fixed step that has become too
// coarse, and the grading CSV.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dem_adapter_support.hpp"

using namespace partita;
using partita::test::monitor;
namespace fs = std::filesystem;

namespace {

std::string dem_yaml(const std::string& breakage) { return test::small_bed_yaml(breakage); }

}  // namespace

TEST_CASE("dem adapter: breakage keys are validated", "[adapters][dem][breakage]") {
  const fs::path out = fs::temp_directory_path() / "partita_dem_breakage_keys";
  const std::string ok =
      "breakage: {limit_strength: 1 MPa, reference_size: 2 mm, weibull_modulus: 3, "
      "comminution_limit: 1 mm";
  CHECK_NOTHROW(test::make_dem(dem_yaml(ok + "}\n"), out));
  for (const char* bad : {"weibull_modulus: 0", "weibull_modulus: -3"}) {
    std::string y = ok + "}\n";
    y.replace(y.find("weibull_modulus: 3"), 18, bad);
    CHECK_THROWS_WITH(test::make_dem(dem_yaml(y), out), Catch::Contains("weibull_modulus"));
  }
  for (const char* key : {"limit_strength", "reference_size", "comminution_limit"}) {
    std::string y = ok + "}\n";
    const auto at = y.find(key);
    const auto end = y.find_first_of(",}", at);
    y.replace(at, end - at, std::string(key) + ": -1");
    INFO(y);
    CHECK_THROWS_WITH(test::make_dem(dem_yaml(y), out), Catch::Contains(key));
  }
  CHECK_THROWS_WITH(test::make_dem(dem_yaml(ok + ", pattern: apolonian-14}\n"), out),
                    Catch::Contains("apollonian-14"));
  CHECK_THROWS_WITH(test::make_dem(dem_yaml(ok + ", mass: kept}\n"), out), Catch::Contains("restored"));
  CHECK_NOTHROW(test::make_dem(dem_yaml(ok + ", below_limit: powder}\n"), out));
  CHECK_THROWS_WITH(test::make_dem(dem_yaml(ok + ", below_limit: dust}\n"), out),
                    Catch::Contains("below_limit") && Catch::Contains("powder"));
  // d_min above every particle: accepted (a warning says nothing can break)
  std::string big = ok + "}\n";
  big.replace(big.find("comminution_limit: 1 mm"), 23, "comminution_limit: 5 mm");
  auto s = test::make_dem(dem_yaml(big), out);
  for (int k = 0; k < 200; ++k) s->advance(s->stable_time_step());
  CHECK(monitor(*s, "breakage.events") == 0.0);
}

TEST_CASE("dem adapter: fragments lower the stable step, monitors and the grading follow",
          "[adapters][dem][breakage]") {
  const fs::path out = fs::temp_directory_path() / "partita_dem_breakage_run";
  fs::create_directories(out / "vtk");
  // weak granules: they break when the bed lands on the floor
  auto s = test::make_dem(dem_yaml("breakage: {limit_strength: 0.2 MPa, reference_size: 2 mm, "
                         "weibull_modulus: 3, comminution_limit: 0.5 mm, pattern: equal-4}\n"),
                out);
  s->write_output(OutputFrame{out / "vtk", "p", 0, s->time(), {}});
  const double dt0 = s->stable_time_step();
  const double n0 = monitor(*s, "particles");
  int steps = 0;
  while (monitor(*s, "breakage.events") == 0.0 && steps < 50000) {
    s->advance(s->stable_time_step());
    ++steps;
  }
  INFO(steps << " steps, " << monitor(*s, "breakage.events") << " events");
  REQUIRE(monitor(*s, "breakage.events") > 0.0);
  const double events = monitor(*s, "breakage.events");
  CHECK(monitor(*s, "particles") == n0 + 3.0 * events);  // equal-4: one parent, four fragments
  CHECK(monitor(*s, "breakage.mass_lost") > 0.0);
  CHECK(monitor(*s, "breakage.fragments") == 4.0 * events);
  // equal-4 fragments are 0.4495 of the parent's radius: the Rayleigh step falls alike
  CHECK(s->stable_time_step() < 0.5 * dt0);
  CHECK(monitor(*s, "stable_time_step") == s->stable_time_step());
  // a step above the new stable one (breakage inside a window) is split into stable steps: the
  // clock advances by the whole step; a fixed substep count is stopped by the core before the
  // next window (tests/app/test_run_services.cpp)
  const double t0 = s->time();
  CHECK_NOTHROW(s->advance(dt0));
  CHECK(s->time() == Approx(t0 + dt0).epsilon(1e-12));
  s->write_output(OutputFrame{out / "vtk", "p", 1, s->time(), {}});
  std::ifstream csv(out / "p_grading.csv");
  std::stringstream text;
  text << csv.rdbuf();
  const std::string t = text.str();
  CHECK(t.rfind("time_s,diameter_m,passing\n", 0) == 0);
  // both frames end with 1 passing the largest size
  std::size_t ones = 0;
  for (std::size_t at = t.find(",1\n"); at != std::string::npos; at = t.find(",1\n", at + 1))
    ++ones;
  CHECK(ones == 2);
  fs::remove_all(out);
}
