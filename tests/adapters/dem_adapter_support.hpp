#pragma once
// Shared by the DEM adapter tests: a DEM participant built from YAML text as the core builds it,
// and its monitor values by name (thin names over tests/support/adapter_solver.hpp).
#include <filesystem>
#include <memory>
#include <string>

#include "../support/adapter_solver.hpp"

namespace partita::test {

inline std::unique_ptr<Solver> make_dem(const std::string& yaml, const std::filesystem::path& out,
                                        const std::filesystem::path& case_dir =
                                            std::filesystem::path(PARTITA_SOURCE_DIR)) {
  return make_solver("dem", yaml, case_dir, out);
}

inline double monitor(const Solver& s, const std::string& name) { return monitor_value(s, name); }

/// A small bed: 72 glass granules of 2.5 and 2.0 mm in a 1 cm box open at the top, under the
/// 4 x 4 rectangle "plate" at z = 10.2 mm; `extra` adds keys (breakage, gravity, ...).
inline std::string small_bed_yaml(const std::string& extra = "") {
  return "solver: dem\n"
         "materials: {glass: {youngs_modulus: 200 MPa, poisson_ratio: 0.23, density: 400},\n"
         "            steel: {youngs_modulus: 250 GPa, poisson_ratio: 0.3, density: 7850}}\n"
         "interactions: [{pair: [glass, glass]}, {pair: [glass, steel], friction: 0.1}]\n"
         "particles: {material: glass, generate: {box: {origin: [0, 0, 0], size: [0.01, 0.01, "
         "0.01]},\n"
         "            diameters: [2.5 mm, 2.0 mm], porosity: 0.55, seed: 3}}\n"
         "walls: [{box: {origin: [0, 0, 0], size: [0.01, 0.01, 0.02]}, open: [zmax], material: "
         "steel}]\n"
         "meshes: [{name: plate, rectangle: {origin: [0, 0, 0.0102], size: [0.01, 0.01], cells: "
         "[4, 4]}, material: steel}]\n" +
         extra;
}

}  // namespace partita::test
