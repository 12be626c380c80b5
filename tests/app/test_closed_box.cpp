// Granules inside a closed FE hollow box whose inner surface (six faces, their edges and corners)
// is the DEM's container, handed over at set-up (tests/inputs/hollow_box/):
// - at rest, the box receives the granules' whole weight m g (static equilibrium: nothing else
//   holds them) within 0.5 %, and the horizontal forces cancel within 0.5 % of it (Hex8 and
//   Hex20 walls);
// - the rigid-walled limit: 8 spheres pressed into the cavity of a box 1000 times stiffer than
//   aluminium load each inner face as the DEM's own rigid planes do, within 1 % (frictionless, so
//   that equilibrium fixes the forces: with friction 0.3 they depend on the path to rest and
//   differed by up to 6 % between FE meshes of 3 to 7 cells per edge; frictionless, by 1e-6,
//   whether the spheres touch the triangulated faces inside a triangle, on an edge or at a vertex).

#include <catch2/catch.hpp>

#include "../support/monitor_csv.hpp"
#include "../support/run_command.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using partita::test::MonitorCsv;
using partita::test::quote;

namespace {

fs::path run_input(const std::string& input, const std::string& tag,
                   const std::vector<std::string>& sets = {}) {
  std::string set;
  for (const auto& k : sets) set += " --set " + quote(k);
  const fs::path dir =
      fs::temp_directory_path() / ("partita_" + tag + "_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/hollow_box" / input).string()) +
      " --output " + quote(dir.string()) + set);
  INFO(r.output);
  REQUIRE(r.status == 0);
  return dir;
}

}  // namespace

TEST_CASE("closed FE box: granules at rest inside load it with their weight",
          "[app][handover][hollow][slow]") {
  // Hex8 (6 x 6 x 6 cells across the cavity): the inner surface's Quad4 faces make 2 triangles
  // each; Hex20 (3 x 3 x 3 cells, for the test's time): Quad8 faces, 6 triangles each
  const std::string element = GENERATE(as<std::string>{}, "hex8", "hex20");
  INFO("element " << element);
  std::vector<std::string> sets = {"participants.box.mesh.element=" + element};
  if (element == "hex20") sets.push_back("participants.box.mesh.box.cells=[3, 3, 3]");
  const fs::path dir = run_input("closed_box.yaml", "closed_box", sets);
  const MonitorCsv csv = MonitorCsv::read(dir / "forces.csv");
  REQUIRE(csv.rows.size() > 100);
  auto mean = csv.mean_over_last(0.1);  // the bed at rest
  const double weight = mean["granules.mass"] * 9.81;
  REQUIRE(weight > 0.0);
  INFO("weight " << weight << " N; FE box " << mean["box.inner.force_x"] << ", "
                 << mean["box.inner.force_y"] << ", " << mean["box.inner.force_z"] << " N; DEM "
                 << mean["granules.box.force_z"] << " N; kinetic energy "
                 << mean["granules.kinetic_energy"] << " J");
  CHECK(mean["granules.kinetic_energy"] < 1e-3 * weight * 0.01);  // at rest: E_k << m g (1 cm)
  CHECK(-mean["box.inner.force_z"] == Approx(weight).epsilon(0.005));
  CHECK(std::abs(mean["box.inner.force_x"]) < 0.005 * weight);
  CHECK(std::abs(mean["box.inner.force_y"]) < 0.005 * weight);
  // what the FE side received is what the particles put on the surface (conservative exchange)
  CHECK(mean["box.inner.force_z"] == Approx(mean["granules.box.force_z"]).epsilon(0.005));
  fs::remove_all(dir);
}

TEST_CASE("closed FE box: very stiff walls load each face as rigid DEM walls do",
          "[app][handover][hollow][slow]") {
  const fs::path fe = run_input("rigid_fe.yaml", "rigid_fe");
  const fs::path dem = run_input("rigid_dem.yaml", "rigid_dem");
  auto f = MonitorCsv::read(fe / "forces.csv").mean_over_last(0.1);
  auto d = MonitorCsv::read(dem / "forces.csv").mean_over_last(0.1);
  const double weight = d["granules.mass"] * 9.81;
  for (const std::string side : {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}) {
    const std::string c = std::string(1, side[0]);
    const double on_fe = f["box." + side + ".force_" + c];
    const double on_dem = d["granules." + side + ".force_" + c];
    INFO(side << ": FE box " << on_fe << " N, rigid DEM wall " << on_dem << " N");
    CHECK(std::abs(on_dem) > 100 * weight);  // the spheres are pressed in: forces >> weight
    CHECK(on_fe == Approx(on_dem).epsilon(0.01));
  }
  // both at rest (the elastic energy of one contact is about 5e-5 J), and frictionless walls
  // carry the weight on floor and ceiling only: their forces differ by m g (equilibrium)
  CHECK(f["granules.kinetic_energy"] < 1e-9);
  CHECK(d["granules.kinetic_energy"] < 1e-9);
  CHECK(-(f["box.zmin.force_z"] + f["box.zmax.force_z"]) == Approx(weight).epsilon(0.01));
  CHECK(-(d["granules.zmin.force_z"] + d["granules.zmax.force_z"]) == Approx(weight).epsilon(0.01));
  fs::remove_all(fe);
  fs::remove_all(dem);
}
