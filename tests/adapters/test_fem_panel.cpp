// The FEM participant's mesh.panel key: a cellular panel from YAML, its parts as
// energy regions, its cells' faces as coupling interfaces, and bad values refused at their key.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include "../support/adapter_solver.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

namespace {

std::string panel_yaml(const std::string& panel_keys) {
  return "solver: fem\n"
         "mesh:\n"
         "  panel: {origin: [0, 0, 0], footprint: [0.3, 0.2], outer_thickness: 3 mm,\n"
         "          inner_thickness: 2 mm, depth: 0.05,\n"
         "          " +
         panel_keys +
         "}\n"
         "material: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}\n"
         "constraints: [{set: xmin, fix: [x, y, z]}, {set: xmax, fix: [x, y, z]}]\n"
         "interfaces: [{name: c00, face: cell_0_0}, {name: c11, face: cell_1_1}, {name: hit, face: "
         "outer}]\n"
         "analysis: {type: transient, integrator: central-difference, mass: lumped}\n";
}

std::unique_ptr<Solver> make(const std::string& yaml) {
  const auto dir = std::filesystem::temp_directory_path();
  return test::make_solver("fem", yaml, dir, dir);
}

}  // namespace

TEST_CASE("fem panel: a cellular panel from YAML, its cells as interfaces",
          "[adapters][fem][panel]") {
  // frames flush with both x edges and one in the middle, one stringer: 2 x 2 cells, each closed
  // along x and open on one side along y
  auto s = make(panel_yaml(
      "web_thickness: 2 mm, element_size: 0.025, frames: [1 mm, 0.15, 0.299], stringers: [0.1]"));
  // cell 0_0: x in [2 mm, 0.149], y in [0, 0.099]: floor + ceiling + two frames' sides + the
  // stringer's side (its ymin side is open)
  const double a = 0.149 - 0.002, b = 0.099, h = 0.05;
  CHECK(test::find_mesh(*s, "c00").mesh.total_area() ==
        Approx(2 * a * b + 2 * b * h + a * h).epsilon(1e-12));
  const double b1 = 0.2 - 0.101, a1 = 0.298 - 0.151;
  CHECK(test::find_mesh(*s, "c11").mesh.total_area() ==
        Approx(2 * a1 * b1 + 2 * b1 * h + a1 * h).epsilon(1e-12));
  CHECK(test::find_mesh(*s, "hit").mesh.total_area() == Approx(0.3 * 0.2).epsilon(1e-12));
  // the parts are energy regions
  std::vector<std::string> names;
  for (const auto& m : s->monitors()) names.push_back(m.name);
  for (const char* part : {"outer_plate", "inner_plate", "webs"})
    CHECK(std::find(names.begin(), names.end(), std::string(part) + ".strain_energy") !=
          names.end());
}

TEST_CASE("fem panel: bad values are refused at their key", "[adapters][fem][panel]") {
  const auto refused = [](const std::string& keys, const std::string& key,
                          const std::string& what) {
    try {
      make(panel_yaml(
          keys + (keys.find("element_size") == std::string::npos ? ", element_size: 0.025" : "") +
          (keys.find("web_thickness") == std::string::npos ? ", web_thickness: 2 mm" : "")));
    } catch (const Error& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(key) != std::string::npos);
      CHECK(std::string(e.what()).find(what) != std::string::npos);
      return;
    }
    FAIL("accepted: " << keys);
  };
  refused("frames: [0.0005]", "mesh.panel.frames", "reaches beyond the footprint");
  refused("stringers: [0.05, 0.052]", "mesh.panel.stringers", "overlap");
  refused("frames: [0.0025]", "mesh.panel.frames", "slivers");
  refused("frames: [0.1], web_thickness: 0", "web_thickness", "");
  refused("element_size: 1e-6", "mesh.panel.element_size", "cells");
}
