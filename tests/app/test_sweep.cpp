// Parametric sweeps through the executable: every variant differs from the case only in the
// swept value, a failing variant leaves the others' rows and an error row in sweep.csv, and two
// jobs at once write the same files as one.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kCase = fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/sweep/tube_sweep.yaml";

fs::path scratch(const std::string& name) { return partita::test::scratch_dir("sweep", name); }

std::string read_all(const fs::path& p) { return partita::test::read_file(p); }

partita::test::CommandResult run(const std::string& args, const std::string& env = "") {
  return partita::test::run_command(env + quote(PARTITA_EXECUTABLE) + " run " +
                                    quote(kCase.string()) + " " + args);
}

std::set<std::string> pngs_under(const fs::path& dir) {
  std::set<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().extension() == ".png") found.insert(fs::relative(e.path(), dir).string());
  return found;
}

std::vector<std::string> csv_lines(const fs::path& p) {
  std::vector<std::string> l;
  std::ifstream in(p);
  for (std::string s; std::getline(in, s);) l.push_back(s);
  return l;
}

}  // namespace

TEST_CASE("sweep: variants differ only in the swept value, the summary has one row each",
          "[app][sweep][slow]") {
  const fs::path dir = scratch("plain");
  // with the plots (the test suite turns them off): sweep.png and each variant's own
  const auto r = run("--jobs 2 --output " + quote(dir.string()), "PARTITA_NO_PLOTS=0 ");
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto rows = csv_lines(dir / "sweep.csv");
  REQUIRE(rows.size() == 4);
  CHECK(rows[0] == "variant,amplitude,status,max_outlet_pressure,final_mid_area");
  const YAML::Node base = YAML::LoadFile(kCase.string());
  for (const std::string a : {"1.0", "3.0", "5.0"}) {
    const fs::path v = dir / ("amplitude=" + a);
    INFO(v);
    REQUIRE(fs::exists(v / "tube.csv"));
    YAML::Node written = YAML::LoadFile((v / "variant.yaml").string());
    CHECK(written["participants"]["fluid"]["inlet_amplitude"].as<double>() == std::stod(a));
    // everything else as in the case file: put the base value back and compare the dumps
    written["participants"]["fluid"]["inlet_amplitude"] =
        base["participants"]["fluid"]["inlet_amplitude"];
    YAML::Emitter e1, e2;
    e1 << base;
    e2 << written;
    std::string b = e1.c_str(), w = e2.c_str();
    CHECK(YAML::Load(b)["sweep"].IsDefined());
    CHECK(w == b);
  }
  // the outlet pressure is driven by the inlet velocity: a larger amplitude, a larger peak
  std::vector<double> peak;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    std::stringstream s(rows[i]);
    std::string cell;
    for (int c = 0; c < 4; ++c) std::getline(s, cell, ',');
    peak.push_back(std::stod(cell));
  }
  CHECK(peak[0] < peak[1]);
  CHECK(peak[1] < peak[2]);
  CHECK(fs::exists(dir / "sweep.png"));
  for (const std::string a : {"1.0", "3.0", "5.0"})
    CHECK(fs::exists(dir / ("amplitude=" + a) / "tube.png"));
  fs::remove_all(dir);
}

TEST_CASE("sweep: two jobs at once write the same files as one", "[app][sweep][slow]") {
  const fs::path one = scratch("jobs1"), two = scratch("jobs2");
  REQUIRE(run("--jobs 1 --output " + quote(one.string())).status == 0);
  // --no-plots reaches every variant: no PNG anywhere (the environment variable alone in `one`)
  REQUIRE(run("--jobs 2 --no-plots --output " + quote(two.string()), "PARTITA_NO_PLOTS=0 ")
              .status == 0);
  CHECK(pngs_under(one).empty());
  CHECK(pngs_under(two).empty());
  CHECK(read_all(one / "sweep.csv") == read_all(two / "sweep.csv"));
  for (const std::string a : {"1.0", "3.0", "5.0"})
    for (const std::string f : {"tube.csv", "coupling.csv"}) {
      INFO(a << " " << f);
      CHECK(read_all(one / ("amplitude=" + a) / f) == read_all(two / ("amplitude=" + a) / f));
    }
  fs::remove_all(one);
  fs::remove_all(two);
}

TEST_CASE("sweep: a failing variant is reported and the others go on", "[app][sweep][slow]") {
  const fs::path dir = scratch("failing");
  // one iteration per window, and an unconverged window is an error: that variant stops in its
  // first window (a failure of the run, not of the input: the others go on)
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " + quote(kCase.string()) +
      " --set 'sweep.parameters[0]={key: coupling.max_iterations, values: [100, 1, 100], label: "
      "iterations}' --set coupling.on_max_iterations=error --output " + quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("1 of 3 variants failed") != std::string::npos);
  const auto rows = csv_lines(dir / "sweep.csv");
  REQUIRE(rows.size() == 4);
  CHECK(rows[1].rfind("iterations=100,100,ok,", 0) == 0);
  CHECK(rows[2].find("failed (exit 1)") != std::string::npos);
  CHECK(rows[3].rfind("iterations=100,100,", 0) == 0);
  fs::remove_all(dir);
}

TEST_CASE("sweep: a value its key does not accept is refused before any variant runs",
          "[app][sweep]") {
  const fs::path dir = scratch("refused");
  // 2 cells is below the tube's minimum of 3: refused at the value's line, nothing written
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " + quote(kCase.string()) +
      " --set 'sweep.parameters[0]={key: participants.fluid.cells, values: [20, 2, 30], label: "
      "cells}' --set participants.fluid.cells=20 --set participants.solid.cells=20 --output " +
      quote((dir / "out").string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(r.output.find("the swept value 2 of participants.fluid.cells") != std::string::npos);
  CHECK(r.output.find("out of range") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}
