// Monitor PNGs (app/plot_monitors.py): one panel per unit, so a count, a mass, forces and an
// energy never share one y axis. The script's own listing of its panels is checked,
// then the PNG is drawn where matplotlib is installed (build.sh installs it). The runs of the
// test suite draw none (PARTITA_NO_PLOTS=1, tests/main.cpp): the switch is checked here.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

TEST_CASE("monitor plots: one panel per unit", "[app][plots]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_plots_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path csv = dir / "mixed.csv";
  std::ofstream(csv) << "time [s],g.contacts,g.mass [kg],g.plate.force_z [N],p.bottom.force_z [N],"
                        "g.kinetic_energy [J]\n"
                        "0,1,2,3,4,5\n1e-3,2,3,4,5,6\n2e-3,3,3,4,5,7\n";
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string script = (fs::path(PARTITA_SOURCE_DIR) / "app" / "plot_monitors.py").string();
  const auto listed =
      partita::test::run_command(python + " " + quote(script) + " --list-panels " + quote(csv));
  INFO(listed.output);
  REQUIRE(listed.status == 0);
  // four units, four panels, in the order of the columns; the two forces share theirs
  CHECK(listed.output ==
        "[]: g.contacts\n"
        "[kg]: g.mass [kg]\n"
        "[N]: g.plate.force_z [N], p.bottom.force_z [N]\n"
        "[J]: g.kinetic_energy [J]\n");
  const auto has_matplotlib = partita::test::run_command(python + " -c 'import matplotlib'");
  if (has_matplotlib.status == 0) {
    const auto drawn = partita::test::run_command(python + " " + quote(script) + " " + quote(csv));
    INFO(drawn.output);
    CHECK(drawn.status == 0);
    CHECK(fs::file_size(dir / "mixed.png") > 1000);
  }
  fs::remove_all(dir);
}

// Quantities of unrelated size get panels of their own, even of one unit or none: a count never
// shares an axis with a ratio, nor a column with one more than 100 times smaller; a panel holds
// at most 6 lines; a time of -1 ("not yet") is not drawn; a case of one participant has nothing
// coupled to plot.
TEST_CASE("monitor plots: unrelated sizes apart, few lines a panel, placeholders masked",
          "[app][plots]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_plots_sizes_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string script = (fs::path(PARTITA_SOURCE_DIR) / "app" / "plot_monitors.py").string();
  const auto panels = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    const auto r = partita::test::run_command(python + " " + quote(script) + " --list-panels " +
                                              quote(dir / name));
    INFO(r.output);
    REQUIRE(r.status == 0);
    return r.output;
  };
  // coupling.csv: iterations (a count) beside an imbalance of 4e-8, over time, not the window
  CHECK(panels("coupling.csv",
               "window,time [s],iterations,imbalance force a->b\n"
               "0,0,0,0\n1,0.1,3,4e-8\n2,0.2,5,3e-8\n") ==
        "[]: iterations\n[]: imbalance force a->b\n");
  // one participant: iterations of 1 and nothing else
  CHECK(panels("single.csv", "window,time [s],iterations\n0,0,1\n1,0.1,1\n2,0.2,1\n") ==
        "(no plot: nothing coupled)\n");
  // a particle count beside contacts per particle; failed elements beside a plastic strain; a
  // first failure time of -1 until it happens
  CHECK(panels("bed.csv",
               "time [s],g.particles,g.contacts_per_particle,h.failed_elements,"
               "h.max_equivalent_plastic_strain,h.first_failure_time [s]\n"
               "0,1612,0,0,0,-1\n1e-3,1612,4.2,0,0.1,-1\n2e-3,1610,4.1,3,0.31,1.5e-3\n") ==
        "[]: g.particles\n"
        "[]: g.contacts_per_particle, h.max_equivalent_plastic_strain\n"
        "[]: h.failed_elements\n"
        "[s]: h.first_failure_time [s] (-1 not drawn)\n");
  // (the two counts are 500 times apart; the two ratios 14 times)
  // 8 energies of one size: no panel holds more than 6 lines, and every one is drawn once
  std::string header = "time [s]", row0 = "0", row1 = "1";
  for (int k = 0; k < 8; ++k) {
    header += ",p.e" + std::to_string(k) + " [J]";
    row0 += ",0";
    row1 += "," + std::to_string(10 + k);
  }
  const std::string listed = panels("energy.csv", header + "\n" + row0 + "\n" + row1 + "\n");
  std::istringstream lines(listed);
  std::string line;
  int drawn = 0, panel_count = 0;
  while (std::getline(lines, line)) {
    const int n = static_cast<int>(std::count(line.begin(), line.end(), ',')) + 1;
    CHECK(n <= 6);
    drawn += n;
    ++panel_count;
  }
  CHECK(drawn == 8);
  CHECK(panel_count == 2);
  fs::remove_all(dir);
}

// `partita run --no-plots` and PARTITA_NO_PLOTS: the run's CSV files without their PNGs; an
// unknown value of the variable warns, names what is allowed, and draws them.
TEST_CASE("monitor plots: --no-plots and PARTITA_NO_PLOTS leave the PNGs out", "[app][plots]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_no_plots_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string run = quote(PARTITA_EXECUTABLE) + " run " +
                          quote(PARTITA_SOURCE_DIR "/tests/inputs/sweep/tube_sweep.yaml") +
                          " --no-sweep --threads 1 --set time.end=0.03 --output ";
  auto files = [](const fs::path& d, const std::string& ext) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(d)) n += e.path().extension() == ext;
    return n;
  };
  for (const std::string how : {"PARTITA_NO_PLOTS=0 ", "PARTITA_NO_PLOTS=1 "}) {
    const std::string option = how == "PARTITA_NO_PLOTS=0 " ? " --no-plots" : "";
    const auto r = partita::test::run_command(how + run + quote((dir / "off").string()) + option);
    INFO(how << option << "\n" << r.output);
    REQUIRE(r.status == 0);
    CHECK(files(dir / "off", ".csv") >= 2);  // coupling.csv and the monitor tube.csv
    CHECK(files(dir / "off", ".png") == 0);
    CHECK(r.output.find("PNG") == std::string::npos);
    fs::remove_all(dir / "off");
  }
  const auto r = partita::test::run_command("PARTITA_NO_PLOTS=maybe " + run +
                                            quote((dir / "on").string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("PARTITA_NO_PLOTS='maybe' is not a switch (allowed: 1,") !=
        std::string::npos);
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  if (partita::test::run_command(python + " -c 'import matplotlib'").status == 0)
    CHECK(files(dir / "on", ".png") == files(dir / "on", ".csv"));
  fs::remove_all(dir);
}

// A sweep's variants of one quantity can span orders of magnitude (a far wall's force from 0.1 N
// for soft granules to 45 N for stiff ones): a variant more than 100 times the smallest of its
// panel starts a panel of its own (its own y range), at most 6 variants a panel, the panels in
// the order of their first variant.
TEST_CASE("sweep plot: variants of unrelated size on panels of their own", "[app][plots]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_sweep_plots_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string script = (fs::path(PARTITA_SOURCE_DIR) / "app" / "plot_sweep.py").string();
  std::string args;
  const std::vector<std::pair<std::string, double>> peaks = {
      {"2MPa", 0.1}, {"20MPa", 0.12}, {"200MPa", 1.0}, {"2GPa", 3.0}, {"20GPa", 44.0}, {"200GPa", 45.0}};
  for (const auto& [label, peak] : peaks) {
    const fs::path csv = dir / (label + ".csv");
    std::ofstream(csv) << "time [s],far.force_z [N]\n0,0\n0.1," << peak / 2 << "\n0.2," << -peak
                       << "\n";
    args += " " + label + " " + quote(csv);
  }
  const auto listed = partita::test::run_command(python + " " + quote(script) +
                                                 " --list-panels " + quote(dir / "sweep.png") +
                                                 " far.force_z" + args);
  INFO(listed.output);
  REQUIRE(listed.status == 0);
  // 0.1 N opens the first panel, which takes up to 100 x 0.1 = 10 N; 44 N opens the second
  CHECK(listed.output == "2MPa, 20MPa, 200MPa, 2GPa\n20GPa, 200GPa\n");
  CHECK_FALSE(fs::exists(dir / "sweep.png"));  // listing draws nothing
  fs::remove_all(dir);
}
