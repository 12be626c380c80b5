// Every case shipped under cases/ is valid: `partita check` reads it completely (parameters,
// meshes, particle files, the participants' set-up, the sweep's variants) and exits 0. Keeps the
// cases from rotting when a key is renamed or a default changes. Files whose name starts with
// '_' are scratch copies and are skipped; checks.yaml files are read by tests/cases.
// cases/scale/scale.yaml is checked with a smaller granule box: check builds each participant, and
// its 10^6 granules' packing took 18 of the test's 22 s of CPU; every key is still read and
// validated and the set-up built, with 3 thousand granules.
// cases/double_hull_impact/seeds.yaml (and seeds_collision.yaml) reads a bed that the case's
// own commands make first (make_section.py, then the fill's two runs, into out/seeds-bed:
// README.md "Variants, commands and times"); it is checked with a small generated bed in one
// cell instead of that file.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;

TEST_CASE("shipped cases: partita check accepts every case file under cases/",
          "[app][cases][slow]") {
  const fs::path root = fs::path(PARTITA_SOURCE_DIR) / "cases";
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const fs::path f = entry.path();
    if (!entry.is_regular_file() || f.extension() != ".yaml") continue;
    const std::string name = f.filename().string();
    if (name.rfind('_', 0) == 0 || name == "checks.yaml") continue;
    files.push_back(f);
  }
  REQUIRE(files.size() >= 10);
  for (const auto& f : files) {
    const std::string dir = f.parent_path().filename().string(), file = f.filename().string();
    std::string smaller;
    if (dir == "scale" && file == "scale.yaml")
      smaller = " --set 'participants.granules.particles.generate.box.size=[0.05, 0.05, 0.05]'";
    if (dir == "double_hull_impact" && (file == "seeds.yaml" || file == "seeds_collision.yaml"))
      smaller =
          " --set 'participants.granules.particles={material: granule, generate: {box: {origin: "
          "[0.005, 0.005, 0.005], size: [0.03, 0.03, 0.03]}, diameters: [4 mm, 3.125 mm, 2.5 mm], "
          "porosity: 0.5}}'";
    const auto r = partita::test::run_command(partita::test::quote(PARTITA_EXECUTABLE) +
                                              " check " + partita::test::quote(f.string()) +
                                              smaller);
    INFO(f.string() << "\n" << r.output);
    CHECK(r.status == 0);
  }
}
