// Monitor PNGs (app/plot_monitors.py): one panel per unit, so a count, a mass, forces and an
// energy never share one y axis (issue 26). The script's own listing of its panels is checked,
// then the PNG is drawn where matplotlib is installed (build.sh installs it).

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

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
