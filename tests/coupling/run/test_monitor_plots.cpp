// A monitor's plots against another of its quantities (monitors[].plots): the run lists them in
// DIR/<name>.plots for app/plot_monitors.py; a name that is not one of the monitor's quantities,
// a y equal to its x or two plots of one x are errors at the key.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "../ode_participant.hpp"
#include "../oscillator_participants.hpp"
#include "partita/run/case_run.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::run;

namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  const fs::path d =
      fs::temp_directory_path() / ("partita_monitor_plots_test_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

Registries registries() {
  Registries r = test::test_registries();
  test::add_oscillator_solvers(r);
  return r;
}

std::string oscillators(const std::string& plots) {
  return "case: oscillators\n"
         "time: {window: 1.0e-3, end: 0.01}\n"
         "participants:\n"
         "  mass: {solver: test-mass, force: 2.0, v0: 1.0}\n"
         "  spring: {solver: test-spring}\n"
         "coupling:\n"
         "  scheme: explicit-serial\n"
         "  exchanges:\n"
         "    - {data: displacement, from: mass.point, to: spring.point}\n"
         "    - {data: force, from: spring.point, to: mass.point}\n"
         "monitors:\n"
         "  - {name: m, quantities: [mass.x, mass.kinetic_energy, spring.elastic_energy]" +
         plots + "}\n";
}

// The error of building the case; "no error" when it builds.
std::string error_of(const fs::path& dir, const std::string& text) {
  std::ofstream(dir / "case.yaml") << text;
  RunOptions o;
  o.output_dir = dir / "out";
  o.check_only = true;
  const Registries r = registries();
  try {
    CaseRun run(dir / "case.yaml", r, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("monitor plots: a monitor's quantities against another, listed for the plot script",
          "[coupling][case][plots]") {
  const fs::path dir = scratch();
  SECTION("the run lists x, then its y, as the CSV names them") {
    std::ofstream(dir / "case.yaml") << oscillators(
        ", plots: [{x: mass.x, y: [mass.kinetic_energy, spring.elastic_energy]}]");
    RunOptions o;
    o.output_dir = dir / "out";
    const Registries r = registries();
    CaseRun run(dir / "case.yaml", r, o);
    run.run();
    std::ifstream in(o.output_dir / "m.plots");
    std::stringstream text;
    text << in.rdbuf();
    CHECK(text.str() == "mass.x,mass.kinetic_energy,spring.elastic_energy\n");
    // the CSV has those columns
    std::ifstream csv(o.output_dir / "m.csv");
    std::string header;
    std::getline(csv, header);
    CHECK(header.find("mass.x [m]") != std::string::npos);
    CHECK(header.find("spring.elastic_energy [J]") != std::string::npos);
  }
  SECTION("a monitor without plots leaves no list, not even an earlier run's") {
    fs::create_directories(dir / "out");
    std::ofstream(dir / "out" / "m.plots") << "mass.x,mass.kinetic_energy\n";
    std::ofstream(dir / "case.yaml") << oscillators("");
    RunOptions o;
    o.output_dir = dir / "out";
    const Registries r = registries();
    CaseRun run(dir / "case.yaml", r, o);
    run.run();
    CHECK(!fs::exists(o.output_dir / "m.plots"));
  }
  SECTION("a quantity the monitor does not record: the key, the monitor's quantities") {
    const std::string e = error_of(dir, oscillators(", plots: [{x: mass.xx, y: [mass.kinetic_energy]}]"));
    INFO(e);
    CHECK(e.find("case.yaml:") != std::string::npos);
    CHECK(e.find("monitors[0].plots[0].x") != std::string::npos);
    CHECK(e.find("'mass.xx' is not one of the quantities of monitor 'm'") != std::string::npos);
    CHECK(e.find("mass.x, mass.kinetic_energy, spring.elastic_energy") != std::string::npos);
    CHECK(e.find("did you mean 'mass.x'") != std::string::npos);
    // a quantity the participant reports, but the monitor does not record
    const std::string y = error_of(dir, oscillators(", plots: [{x: mass.x, y: [mass.damping_work]}]"));
    INFO(y);
    CHECK(y.find("monitors[0].plots[0].y") != std::string::npos);
    CHECK(y.find("add it to the monitor's quantities") != std::string::npos);
  }
  SECTION("a y equal to x, two plots of one x, a plot without y: errors") {
    CHECK(error_of(dir, oscillators(", plots: [{x: mass.x, y: [mass.x]}]"))
              .find("is the plot's x") != std::string::npos);
    CHECK(error_of(dir, oscillators(", plots: [{x: mass.x, y: [mass.kinetic_energy]}, "
                                    "{x: mass.x, y: [spring.elastic_energy]}]"))
              .find("two plots of monitor 'm' have x 'mass.x'") != std::string::npos);
    const std::string e = error_of(dir, oscillators(", plots: [{x: mass.x}]"));
    INFO(e);
    CHECK(e.find("monitors[0].plots[0]") != std::string::npos);
    CHECK(e.find("y") != std::string::npos);
    CHECK(e != "no error");
  }
  fs::remove_all(dir);
}
