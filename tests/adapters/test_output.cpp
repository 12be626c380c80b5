// The VTK files the DEM and FEM adapters write (through interface/vtk_xml), read back with VTK's
// own readers: in every format the same values; the arrays, names and cell types users' ParaView
// states rely on; values checked against what they must be (constraints, sums, closed forms).

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <unistd.h>

#include "../support/vtk_read.hpp"
#include "dem_adapter_support.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using partita::test::read_vtk;
namespace fs = std::filesystem;

namespace {

const vtk::Format kFormats[] = {vtk::Format::ascii, vtk::Format::binary, vtk::Format::zlib};

// The scratch folders, removed when the test program ends.
struct Scratch {
  std::vector<fs::path> dirs;
  ~Scratch() {
    std::error_code ec;
    for (const auto& d : dirs) fs::remove_all(d, ec);
  }
};
Scratch g_scratch;

fs::path scratch(const std::string& name) {
  // the process id in the name: two suites running at once (two checkouts) never share it
  const fs::path dir = fs::temp_directory_path() / ("partita_test_adapter_output_" + name + "_" +
                                                    std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  g_scratch.dirs.push_back(dir);
  return dir;
}

// Every file of the frame written in each format into its own folder; returns the folders.
std::vector<fs::path> write_every_format(Solver& s, const fs::path& dir,
                                         vtk::Precision p = vtk::Precision::float64) {
  std::vector<fs::path> dirs;
  for (const vtk::Format f : kFormats) {
    const fs::path d = dir / std::string(vtk::to_string(f)) / std::string(vtk::to_string(p));
    fs::create_directories(d);
    s.write_output(OutputFrame{d, "p", 3, s.time(), {f, 1, 1u << 20, p}});
    dirs.push_back(d);
  }
  return dirs;
}

}  // namespace

TEST_CASE("fem adapter: the .vtu's contact_force is the indenters' force on each node",
          "[adapters][fem][output][contact]") {
  // a driven sphere pressed 0.2 mm into a clamped block's top, one static step: the nodes of
  // the top face under it carry the contact force, every other node none, and their sum is
  // minus the force on the sphere (action and reaction)
  const fs::path dir = scratch("fem_contact");
  auto s = test::make_solver(
      "fem",
      "solver: fem\n"
      "mesh: {box: {origin: [0, 0, 0], size: [0.02, 0.02, 0.01], cells: [4, 4, 2]}}\n"
      "material: {youngs_modulus: 70 GPa, poisson_ratio: 0.3, density: 2700}\n"
      "constraints: [{set: zmin, fix: [x, y, z]}]\n"
      "indenters: [{name: ball, shape: sphere, radius: 0.008, position: [0.01, 0.01, 0.018], face: zmax,\n"
      "             motion: {velocity: [0, 0, -0.0002]}}]\n"
      "analysis: {type: static}\n",
      PARTITA_SOURCE_DIR, dir);
  s->advance(1.0);  // the sphere 0.2 mm into the top
  double force_z = 0.0;
  for (const auto& m : s->monitors())
    if (m.name == "ball.force_z") force_z = m.value;
  REQUIRE(force_z > 0.0);  // pushed back up
  const auto dirs = write_every_format(*s, dir);
  const auto c = read_vtk(dirs[0] / s->output_files()[0].second);
  REQUIRE(c.ok);
  REQUIRE(c.point.count("contact_force") == 1);
  const auto& f = c.point.at("contact_force").values;
  double sum[3] = {0, 0, 0};
  int touched = 0;
  for (std::size_t i = 0; i < c.points; ++i) {
    for (int k = 0; k < 3; ++k) sum[k] += f[3 * i + k];
    if (f[3 * i + 2] != 0.0) {
      ++touched;
      CHECK(c.xyz[3 * i + 2] == Approx(0.01));  // on the top face
      CHECK(f[3 * i + 2] < 0.0);                // pushed down
    }
  }
  CHECK(touched >= 1);
  CHECK(sum[2] == Approx(-force_z).epsilon(1e-9));
  CHECK(std::abs(sum[0]) <= 1e-9 * force_z);
  CHECK(std::abs(sum[1]) <= 1e-9 * force_z);
}

TEST_CASE("fem adapter: the .vtu of every element type, in every format",
          "[adapters][fem][output]") {
  const fs::path dir = scratch("fem");
  const std::vector<std::tuple<std::string, int, int>> elements = {
      {"hex8", 12, 8}, {"hex20", 25, 20}, {"tet4", 10, 4}, {"tet10", 24, 10}};  // VTK cell types
  for (const auto& [element, vtk_type, per_cell] : elements) {
    DYNAMIC_SECTION(element) {
      auto s = test::make_solver(
          "fem",
          "solver: fem\n"
          "mesh: {box: {origin: [0, 0, 0], size: [1, 0.2, 0.2], cells: [4, 1, 1]}, element: " +
              element +
              "}\n"
              "material: {youngs_modulus: 200 GPa, poisson_ratio: 0.3, density: 7850}\n"
              "constraints: [{set: xmin, fix: [x, y, z]}]\n"
              "loads: [{face: zmax, pressure: 100 kPa}]\n"
              "analysis: {type: static}\n",
          PARTITA_SOURCE_DIR, dir);
      s->advance(1.0);
      const auto dirs = write_every_format(*s, dir / element);
      REQUIRE(s->output_files().size() == 1);
      const std::string file = s->output_files()[0].second;
      CHECK(file == "p_fem_000003.vtu");
      std::string first;
      for (const fs::path& d : dirs) {
        INFO(d.string());
        const auto c = read_vtk(d / file);
        INFO(c.text.substr(0, 3000));
        REQUIRE(c.ok);
        if (first.empty()) first = c.text;
        CHECK(c.text == first);        // ascii, raw and zlib: the same values
        REQUIRE(c.types.size() >= 4);  // 4 hexahedra, or the tetrahedra they are cut into
        for (const auto t : c.types) CHECK(t == vtk_type);
        const auto& offsets = c.cells.at("cells").offsets;
        for (std::size_t k = 0; k + 1 < offsets.size(); ++k)
          CHECK(offsets[k + 1] - offsets[k] == per_cell);
        for (const char* name : {"displacement", "velocity", "stress", "von_mises"})
          CHECK(c.point.count(name) == 1);
        CHECK(c.cell.count("region") == 1);
        CHECK(c.active.at("point Scalars") == "von_mises");
        CHECK(c.active.at("point Vectors") == "displacement");
        CHECK(c.active.at("point Tensors") == "stress");
        // the constraint: zero displacement on x = 0; a bent beam elsewhere
        const auto& u = c.point.at("displacement").values;
        double umax = 0.0;
        for (std::size_t i = 0; i < c.points; ++i) {
          const double norm = std::hypot(u[3 * i], u[3 * i + 1], u[3 * i + 2]);
          if (c.xyz[3 * i] == 0.0) CHECK(norm == 0.0);
          umax = std::max(umax, norm);
        }
        CHECK(umax > 0.0);
        // von Mises from the written tensor (VTK's order XX YY ZZ XY YZ XZ)
        const auto& st = c.point.at("stress").values;
        const auto& vm = c.point.at("von_mises").values;
        for (std::size_t i = 0; i < c.points; ++i) {
          const double* t = &st[6 * i];
          const double v =
              std::sqrt(0.5 * ((t[0] - t[1]) * (t[0] - t[1]) + (t[1] - t[2]) * (t[1] - t[2]) +
                               (t[2] - t[0]) * (t[2] - t[0])) +
                        3.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5]));
          CHECK(vm[i] == Approx(v).epsilon(1e-12).margin(1e-9));
        }
      }
    }
  }
}

TEST_CASE("fem adapter: the .vtu carries the equivalent plastic strain of J2 plasticity",
          "[adapters][fem][output][j2]") {
  // a unit cube in uniaxial compression by 300 MPa, yield 200 MPa, linear hardening 20 GPa:
  // eps_p = (sigma - sigma_y) / H = 0.005 (radial return is exact for proportional loading)
  const fs::path dir = scratch("j2");
  auto s = test::make_solver("fem",
                             "solver: fem\n"
                             "mesh: {box: {origin: [0, 0, 0], size: [1, 1, 1], cells: [1, 1, 1]}}\n"
                             "material: {model: j2-plasticity, youngs_modulus: 200 GPa, "
                             "poisson_ratio: 0.3, density: 7850, yield_stress: 200 MPa, "
                             "hardening_modulus: 20 GPa}\n"
                             "constraints: [{set: xmin, fix: [x]}, {set: ymin, fix: [y]}, "
                             "{set: zmin, fix: [z]}]\n"
                             "loads: [{face: zmax, pressure: 300 MPa}]\n"
                             "analysis: {type: static}\n",
                             PARTITA_SOURCE_DIR, dir);
  s->advance(1.0);
  for (const fs::path& d : write_every_format(*s, dir)) {
    INFO(d.string());
    const auto c = read_vtk(d / "p_fem_000003.vtu");
    INFO(c.text);
    REQUIRE(c.ok);
    REQUIRE(c.cell.count("equivalent_plastic_strain") == 1);
    CHECK(c.cell.at("equivalent_plastic_strain").values.at(0) == Approx(0.005).epsilon(1e-8));
  }
}

TEST_CASE("dem adapter: particle and mesh files in every format, forces summing to the monitors",
          "[adapters][dem][output]") {
  const fs::path dir = scratch("dem");
  auto s = test::make_dem(test::small_bed_yaml("gravity: [0, 0, -9.81]\n"), dir);
  // lower the plate onto the bed, 2 um a step, until it touches; 20 steps more: contact forces
  const auto& plate = s->meshes().front();
  REQUIRE(plate.mesh.name() == "plate");
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(plate.mesh.size(), 3);
  double fz = 0.0;
  for (int k = 0, after = 0; k < 5000 && after < 20; ++k) {
    if (fz == 0.0) d.col(2).array() -= 2.0e-6;
    s->read("plate", "displacement", d);
    s->advance(s->stable_time_step());
    fz = test::monitor(*s, "plate.force_z");
    if (fz != 0.0) ++after;
  }
  const double n = test::monitor(*s, "particles");
  CHECK(std::abs(fz) > 0.0);
  const auto dirs = write_every_format(*s, dir);
  std::string first_p, first_m;
  for (const fs::path& dd : dirs) {
    INFO(dd.string());
    const auto p = read_vtk(dd / "p_particles_000003.vtp");
    INFO(p.text.substr(0, 2000));
    REQUIRE(p.ok);
    if (first_p.empty()) first_p = p.text;
    CHECK(p.text == first_p);
    CHECK(static_cast<double>(p.points) == n);
    CHECK(p.cells.at("verts").count == p.points);
    for (const char* name : {"radius", "id", "velocity", "angular_velocity", "force"})
      CHECK(p.point.count(name) == 1);
    for (const double r : p.point.at("radius").values) CHECK((r == 1.25e-3 || r == 1.0e-3));
    const auto& ids = p.point.at("id").ints;
    CHECK(std::set<std::int64_t>(ids.begin(), ids.end()).size() == p.points);  // unique
    const auto m = read_vtk(dd / "p_plate_000003.vtp");
    INFO(m.text.substr(0, 2000));
    REQUIRE(m.ok);
    if (first_m.empty()) first_m = m.text;
    CHECK(m.text == first_m);
    CHECK(m.cells.at("polys").count == 32);  // 4 x 4 cells, two triangles each
    CHECK(m.points == 25);
    // triangle forces and vertex forces both sum to the force on the mesh
    double cell_z = 0.0, point_z = 0.0;
    for (std::size_t t = 0; t < 32; ++t) cell_z += m.cell.at("force").values[3 * t + 2];
    for (std::size_t v = 0; v < 25; ++v) point_z += m.point.at("force").values[3 * v + 2];
    CHECK(cell_z == Approx(fz).epsilon(1e-9));
    CHECK(point_z == Approx(fz).epsilon(1e-9));
    // every triangle takes part in contacts (none taken out): active 1
    REQUIRE(m.cell.count("active") == 1);
    const auto& act = m.cell.at("active");
    CHECK(act.ints.size() + act.values.size() == 32);
    for (const auto a : act.ints) CHECK(a == 1);
    for (const double a : act.values) CHECK(a == 1.0);
    // the plate moved with the displacement it was given
    for (std::size_t v = 0; v < 25; ++v)
      CHECK(m.xyz[3 * v + 2] == Approx(0.0102 + d(0, 2)).epsilon(1e-12));
  }
  // float32 (the case default): the fields rounded to float, coordinates and ids exact
  std::string first32;
  for (const fs::path& dd : write_every_format(*s, dir, vtk::Precision::float32)) {
    const auto p = read_vtk(dd / "p_particles_000003.vtp");
    const auto p64 = read_vtk(dir / "zlib" / "float64" / "p_particles_000003.vtp");
    INFO(dd.string());
    REQUIRE(p.ok);
    if (first32.empty()) first32 = p.text;
    CHECK(p.text == first32);
    CHECK(p.xyz == p64.xyz);
    CHECK(p.point.at("id").ints == p64.point.at("id").ints);
    REQUIRE(p.point.at("force").type == "float");
    const auto& f64 = p64.point.at("force").values;
    for (std::size_t k = 0; k < f64.size(); ++k)
      CHECK(p.point.at("force").values[k] == static_cast<double>(static_cast<float>(f64[k])));
  }
  // a frame that cannot be written: an error, no half-written file
  std::ofstream(dir / "not_a_folder") << "x";
  CHECK_THROWS_AS(s->write_output(OutputFrame{dir / "not_a_folder", "p", 4, s->time(), {}}), Error);
}
