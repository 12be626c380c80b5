// Solver plugins in the stock partita executable (app/plugin_loader.hpp): the example's
// oscillator (examples/out_of_tree_adapter/oscillator_plugin.cpp, built as a plugin by
// tests/CMakeLists.txt) loaded with --plugin or a case's plugins: list, through list, docs, check,
// run, --set, a sweep and --resume, against the exact solution z(t) = z_0 cos(sqrt(k/m) t) that
// the adapter integrates; and the libraries partita must refuse, each named in its error.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "partita/interface/version_number.hpp"

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kPluginDir = PARTITA_TEST_PLUGIN_DIR;
const fs::path kOscillator = kPluginDir / "libpartita_test_plugin_oscillator.so";
const fs::path kExample = fs::path(PARTITA_SOURCE_DIR) / "examples/out_of_tree_adapter";

fs::path broken(const std::string& variant) {
  return kPluginDir / ("libpartita_test_plugin_" + variant + ".so");
}

fs::path scratch(const std::string& name) {
  return partita::test::scratch_dir("plugins", name);
}

partita::test::CommandResult partita_cmd(const std::string& args) {
  return partita::test::run_partita(args);
}

// The last row of a CSV file as numbers.
std::vector<double> last_row(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<double> v;
  std::stringstream s(last);
  for (std::string cell; std::getline(s, cell, ',');) v.push_back(std::stod(cell));
  return v;
}

// m = 2 kg, z_0 = 10 mm at rest: z(t) = z_0 cos(sqrt(k/m) t).
double exact_z(double k, double t) {
  return 0.01 * std::cos(std::sqrt(k / 2.0) * t);
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

const char* kOscillatorCase = R"(case: osc
time: {window: 0.01, end: 1.0}
participants:
  spring: {solver: oscillator, mass: 2 kg, stiffness: 50, displacement: 10 mm}
monitors:
  - {name: motion, quantities: [spring.z, spring.v, spring.energy]}
)";

}  // namespace

TEST_CASE("plugins: the stock partita lists, documents and runs a solver from --plugin",
          "[app][plugins]") {
  REQUIRE(fs::exists(kOscillator));
  const std::string plugin = " --plugin " + quote(kOscillator.string());

  // without the plugin the solver is unknown; with it, it is in the executable's registry
  CHECK(partita_cmd("docs oscillator").status == 1);
  auto r = partita_cmd("list" + plugin);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("oscillator") != std::string::npos);
  CHECK(r.output.find("a mass on a spring along z [plugin libpartita_test_plugin_oscillator.so]") !=
        std::string::npos);
  CHECK(r.output.find("tube1d-fluid") != std::string::npos);  // the built-in ones stay
  r = partita_cmd("docs oscillator" + plugin);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("stiffness") != std::string::npos);
  CHECK(r.output.find("kinetic plus spring energy") != std::string::npos);
  // --plugin before the subcommand works as well
  CHECK(partita_cmd(plugin + " docs oscillator").status == 0);

  // the run: z(1 s) = z_0 cos(5), energy 1/2 k z_0^2 = 2.5 mJ, to round-off
  const fs::path dir = scratch("cli");
  r = partita_cmd("run " + quote((kExample / "oscillator.yaml").string()) + plugin + " --output " +
                  quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  auto row = last_row(dir / "motion.csv");
  REQUIRE(row.size() == 4);
  CHECK(row[0] == Approx(1.0).margin(1e-12));
  CHECK(std::abs(row[1] - exact_z(50, row[0])) < 1e-12);
  CHECK(row[3] == Approx(2.5e-3).epsilon(1e-10));

  // --set reaches the plugin solver's keys: k = 200 N/m, omega = 10 rad/s
  const fs::path dir2 = scratch("set");
  r = partita_cmd("run " + quote((kExample / "oscillator.yaml").string()) + plugin +
                  " --set participants.spring.stiffness=200 --output " + quote(dir2.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  row = last_row(dir2 / "motion.csv");
  REQUIRE(row.size() == 4);
  CHECK(std::abs(row[1] - exact_z(200, row[0])) < 1e-12);
  CHECK(row[3] == Approx(0.5 * 200 * 1e-4).epsilon(1e-10));
  fs::remove_all(dir);
  fs::remove_all(dir2);
}

TEST_CASE("plugins: a case's plugins list, relative to the case file, with check and --resume",
          "[app][plugins]") {
  const fs::path dir = scratch("case");
  fs::create_directories(dir / "lib");
  fs::copy_file(kOscillator, dir / "lib" / "libosc.so");
  const fs::path case_file = dir / "osc.yaml";
  write(case_file, std::string("plugins: [lib/libosc.so]\n") + kOscillatorCase +
                       "output: {restart: {every_windows: 40}}\n");
  auto r = partita_cmd("check " + quote(case_file.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("is valid") != std::string::npos);

  // run from another folder: the path is the case file's, not the working directory's
  const fs::path out = dir / "out";
  r = partita::test::run_command("cd / && " + quote(PARTITA_EXECUTABLE) + " run " +
                                 quote(case_file.string()) + " --output " + quote(out.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  bool restart_at_end = false;  // restart.at_end: out/restart/w<window 100, zero-padded>.bin
  for (const auto& e : fs::directory_iterator(out / "restart"))
    restart_at_end = restart_at_end || e.path().filename().string().ends_with("100.bin");
  CHECK(restart_at_end);
  // continue to t = 2 s from the end of the first run (restart.at_end): same exact solution
  r = partita_cmd("run " + quote(case_file.string()) + " --resume " + quote(out.string()) +
                  " --set time.end=2.0");
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto row = last_row(out / "motion.csv");
  REQUIRE(row.size() == 4);
  CHECK(row[0] == Approx(2.0).margin(1e-12));
  CHECK(std::abs(row[1] - exact_z(50, row[0])) < 1e-12);

  // the same library also on the command line loads once
  r = partita_cmd("check " + quote(case_file.string()) + " --plugin " +
                  quote((dir / "lib" / "libosc.so").string()));
  INFO(r.output);
  CHECK(r.status == 0);
  fs::remove_all(dir);
}

TEST_CASE("plugins: a sweep's variants run with the --plugin libraries", "[app][plugins][sweep]") {
  const fs::path dir = scratch("sweep");
  const fs::path case_file = dir / "osc.yaml";
  write(case_file, std::string(kOscillatorCase) + R"(sweep:
  parameters:
    - {key: participants.spring.stiffness, values: [50, 200], label: k}
  results:
    - {name: z_end, monitor: motion, column: spring.z}
)");
  const auto r =
      partita_cmd("run " + quote(case_file.string()) + " --plugin " + quote(kOscillator.string()) +
                  " --jobs 2 --output " + quote((dir / "out").string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / "out" / "sweep.csv");
  std::string header, line;
  std::getline(in, header);
  CHECK(header == "variant,k,status,z_end");
  int rows = 0;
  while (std::getline(in, line)) {
    INFO(line);
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
    REQUIRE(cells.size() == 4);
    CHECK(cells[2] == "ok");
    CHECK(std::abs(std::stod(cells[3]) - exact_z(std::stod(cells[1]), 1.0)) < 1e-12);
    ++rows;
  }
  CHECK(rows == 2);
  fs::remove_all(dir);
}

TEST_CASE("plugins: each library partita refuses gives one clear error naming it",
          "[app][plugins][errors]") {
  const fs::path dir = scratch("errors");
  auto refuse = [](const std::string& args, const std::vector<std::string>& expected) {
    const auto r = partita_cmd(args);
    INFO(args << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK_FALSE(r.signalled);
    for (const auto& e : expected) CHECK(r.output.find(e) != std::string::npos);
  };
  const fs::path missing = dir / "libnothing.so";
  refuse("list --plugin " + quote(missing.string()), {missing.string(), "no such file"});

  const fs::path text = dir / "libtext.so";
  write(text, "not a shared library\n");
  refuse("list --plugin " + quote(text.string()),
         {text.string(), "cannot be loaded", "libtext.so: "});  // then dlopen's own words

  refuse("list --plugin " + quote(broken("no_entry").string()),
         {broken("no_entry").string(), "not a partita plugin", "partita_plugin_api_version",
          "PARTITA_PLUGIN"});
  refuse("docs --plugin " + quote(broken("other_version").string()),
         {broken("other_version").string(), "built against partita 0.0.0-other",
          std::string("this is partita ") + PARTITA_VERSION_STRING});
  refuse("list --plugin " + quote(broken("builtin_name").string()),
         {broken("builtin_name").string(),
          "mapper 'nearest-neighbor' is already registered by partita itself"});
  refuse("list --plugin " + quote(broken("throws").string()),
         {broken("throws").string(), "its licence file is missing"});
  refuse("list --plugin " + quote(broken("own_copy").string()),
         {broken("own_copy").string(), "carries its own copy of partita",
          "link partita::plugin instead"});

  // two libraries with the same solver name: the second is refused, naming the first
  const fs::path second = dir / "libsecond.so";
  fs::copy_file(kOscillator, second);
  refuse("list --plugin " + quote(kOscillator.string()) + " --plugin " + quote(second.string()),
         {"plugin " + second.string(), "solver 'oscillator' is already registered by plugin " +
                                           fs::canonical(kOscillator).string()});

  // the case's list: a missing library names the case file's line; not a list is refused
  const fs::path case_file = dir / "osc.yaml";
  write(case_file, std::string("plugins: [lib/none.so]\n") + kOscillatorCase);
  refuse("check " + quote(case_file.string()),
         {(dir / "lib/none.so").string(), case_file.string() + ":1", "no such file"});
  write(case_file, std::string("plugins: lib/none.so\n") + kOscillatorCase);
  refuse("check " + quote(case_file.string()),
         {case_file.string() + ":1", "plugins", "expected a list of plugin libraries"});
  // without the plugin, the case's solver is unknown
  write(case_file, kOscillatorCase);
  refuse("check " + quote(case_file.string()),
         {"unknown solver 'oscillator'", "plugins: [LIB] in the case, or partita --plugin LIB"});
  fs::remove_all(dir);
}

TEST_CASE("plugins: partita docs case declares the plugins key", "[app][plugins]") {
  const auto r = partita_cmd("docs case");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("plugins") != std::string::npos);
  CHECK(r.output.find("relative to the case file") != std::string::npos);
}
