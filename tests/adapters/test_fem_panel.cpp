// The FEM participant's mesh.panel key: a cellular panel from YAML (webs by position or by cell
// count and spacing), its parts as energy regions, its cells' faces and the cavity's faces by
// part as coupling interfaces (forces read on interfaces that share nodes add), and bad values
// refused at their key.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

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

// A panel given by cells (2 x 2 of 60 mm, 2 mm webs), clamped at its edges, solved statically.
std::string cells_yaml(const std::string& interfaces) {
  return "solver: fem\n"
         "mesh:\n"
         "  panel: {origin: [0, 0, 0], cells: [2, 2], web_spacing: 0.06, web_thickness: 2 mm,\n"
         "          outer_thickness: 3 mm, inner_thickness: 2 mm, depth: 0.04, element_size: "
         "0.02}\n"
         "material: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}\n"
         "constraints: [{set: xmin, fix: [x, y, z]}, {set: xmax, fix: [x, y, z]},\n"
         "              {set: ymin, fix: [x, y, z]}, {set: ymax, fix: [x, y, z]}]\n"
         "interfaces: " +
         interfaces +
         "\n"
         "analysis: {type: static}\n";
}

using Place = std::tuple<long, long, long>;  // a vertex's position, to 1 nm

Place place_of(const Eigen::Vector3d& x) {
  return {std::lround(x.x() * 1e9), std::lround(x.y() * 1e9), std::lround(x.z() * 1e9)};
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

TEST_CASE("fem panel: the cells form refuses mixing and bad counts at their key",
          "[adapters][fem][panel]") {
  const auto refused = [](const std::string& yaml, const std::string& key,
                          const std::string& what) {
    try {
      make(yaml);
    } catch (const Error& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(key) != std::string::npos);
      CHECK(std::string(e.what()).find(what) != std::string::npos);
      return;
    }
    FAIL("accepted: " << yaml);
  };
  const std::string ok = cells_yaml("[{name: c, face: cavity}]");
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string y = ok;
    const auto at = y.find(from);
    REQUIRE(at != std::string::npos);
    return y.replace(at, from.size(), to);
  };
  // the two forms mixed
  refused(with("cells: [2, 2]", "cells: [2, 2], footprint: [0.1, 0.1]"), "mesh.panel",
          "exclude each other");
  refused(with("cells: [2, 2]", "cells: [2, 2], frames: [0.001]"), "mesh.panel",
          "exclude each other");
  refused(with("cells: [2, 2], web_spacing: 0.06",
               "footprint: [0.122, 0.122], frames: [0.001, 0.121], web_spacing: 0.06"),
          "mesh.panel.web_spacing", "frames and stringers");
  // counts and spacing
  refused(with("cells: [2, 2]", "cells: [0, 2]"), "mesh.panel.cells", "1 <= value");
  refused(with("cells: [2, 2]", "cells: [2]"), "mesh.panel.cells", "2 values");
  refused(with("web_spacing: 0.06", "web_spacing: 0.003"), "mesh.panel.web_spacing",
          "at least 2 web_thickness");
  refused(with("web_spacing: 0.06, ", ""), "mesh.panel.cells", "needs web_spacing");
  refused(with("web_thickness: 2 mm,", ""), "mesh.panel.cells", "needs web_thickness");
  refused(with("origin: [0, 0, 0]", "origin: [0, 0, 0], centre: [0, 0, 0]"), "mesh.panel",
          "exclude each other");
}

TEST_CASE("fem panel: the cells form, its footprint and its closed cells",
          "[adapters][fem][panel]") {
  auto s = make(cells_yaml("[{name: c11, face: cell_1_1}, {name: webs, face: cavity_webs}]"));
  // cell 1_1: x and y in [62 mm, 120 mm] (clear width 58 mm), closed on its four sides
  const double a = 0.058, h = 0.04;
  CHECK(test::find_mesh(*s, "c11").mesh.total_area() ==
        Approx(2 * a * a + 4 * a * h).epsilon(1e-12));
  CHECK(test::find_mesh(*s, "webs").mesh.total_area() == Approx(4 * 4 * a * h).epsilon(1e-12));
  double x_max = 0.0;
  for (const auto& m : s->meshes())
    if (m.mesh.name() == "webs")
      for (Eigen::Index k = 0; k < m.mesh.points().rows(); ++k)
        x_max = std::max(x_max, m.mesh.points()(k, 0));
  CHECK(x_max == Approx(0.122 - 0.002).epsilon(1e-12));  // footprint 2 x 60 + 2 mm, a web flush

  // placed by its centre instead: the footprint about it, whatever the cell count
  std::string centred = cells_yaml("[{name: cavity, face: cavity}]");
  centred.replace(centred.find("origin: [0, 0, 0], cells: [2, 2]"), 32,
                  "centre: [0.5, -0.2, 0.1], cells: [3, 2]");
  auto c = make(centred);
  const auto& pts = test::find_mesh(*c, "cavity").mesh.points();
  const Eigen::RowVector3d lo = pts.colwise().minCoeff(), hi = pts.colwise().maxCoeff();
  CHECK(0.5 * (lo.x() + hi.x()) == Approx(0.5).epsilon(1e-12));
  CHECK(0.5 * (lo.y() + hi.y()) == Approx(-0.2).epsilon(1e-12));
  CHECK(hi.x() - lo.x() == Approx(3 * 0.06 - 0.002).epsilon(1e-12));  // the cavity's walls
  CHECK(lo.z() == Approx(0.1 + 0.003).epsilon(1e-12));                // on the outer plate
}

TEST_CASE("fem panel: forces read on the cavity's parts add where the parts share nodes",
          "[adapters][fem][panel]") {
  // the filling's load on the three parts (as a DEM bed's weight on cavity_outer, cavity_inner
  // and cavity_webs, which share the nodes where a web meets a plate) against the same load
  // summed node by node and read on one interface, cavity: the same static solution, and the
  // same displacement written at a shared node by every part it belongs to
  auto parts =
      make(cells_yaml("[{name: outer, face: cavity_outer}, {name: inner, face: cavity_inner}, "
                      "{name: webs, face: cavity_webs}]"));
  auto whole = make(cells_yaml("[{name: cavity, face: cavity}]"));
  std::map<Place, Eigen::Vector3d> summed;
  double total = 0.0;
  int shared = 0;
  for (const char* part : {"outer", "inner", "webs"}) {
    const auto& m = test::find_mesh(*parts, part).mesh;
    Eigen::MatrixXd f(m.points().rows(), 3);
    for (Eigen::Index k = 0; k < f.rows(); ++k) {
      // a different force at every vertex, not symmetric
      const Eigen::Vector3d p = m.points().row(k).transpose();
      f.row(k) = Eigen::RowVector3d(0.3 * p.y(), -0.2, -1.0 - 10.0 * p.x());
      auto [it, fresh] = summed.try_emplace(place_of(p), Eigen::Vector3d::Zero());
      shared += !fresh;
      it->second += f.row(k).transpose();
      total += f(k, 2);
    }
    parts->read(part, "force", f);
  }
  REQUIRE(shared > 0);  // the webs' feet and heads
  const auto& mc = test::find_mesh(*whole, "cavity").mesh;
  REQUIRE(static_cast<std::size_t>(mc.points().rows()) == summed.size());
  Eigen::MatrixXd fc(mc.points().rows(), 3);
  for (Eigen::Index k = 0; k < fc.rows(); ++k)
    fc.row(k) = summed.at(place_of(mc.points().row(k).transpose())).transpose();
  whole->read("cavity", "force", fc);
  parts->advance(1.0);
  whole->advance(1.0);
  // the parts' received forces sum to the load
  const double received = test::monitor_value(*parts, "outer.force_z") +
                          test::monitor_value(*parts, "inner.force_z") +
                          test::monitor_value(*parts, "webs.force_z");
  CHECK(received == Approx(total).epsilon(1e-12));
  CHECK(test::monitor_value(*whole, "cavity.force_z") == Approx(total).epsilon(1e-12));
  Eigen::MatrixXd uc;
  whole->write("cavity", "displacement", uc);
  std::map<Place, Eigen::Vector3d> u_whole;
  for (Eigen::Index k = 0; k < uc.rows(); ++k)
    u_whole[place_of(mc.points().row(k).transpose())] = uc.row(k).transpose();
  const double scale = uc.cwiseAbs().maxCoeff();
  REQUIRE(scale > 0.0);
  std::map<Place, Eigen::Vector3d> u_parts;
  double worst = 0.0, differs = 0.0;
  for (const char* part : {"outer", "inner", "webs"}) {
    const auto& m = test::find_mesh(*parts, part).mesh;
    Eigen::MatrixXd u;
    parts->write(part, "displacement", u);
    for (Eigen::Index k = 0; k < u.rows(); ++k) {
      const Place at = place_of(m.points().row(k).transpose());
      worst = std::max(worst, (u.row(k).transpose() - u_whole.at(at)).norm());
      const auto [it, fresh] = u_parts.try_emplace(at, u.row(k).transpose());
      if (!fresh) differs = std::max(differs, (it->second - u.row(k).transpose()).norm());
    }
  }
  CHECK(worst <= 1e-9 * scale);
  CHECK(differs == 0.0);  // one node, one displacement
}
