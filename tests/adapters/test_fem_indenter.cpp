// Rigid indenters of the FEM participant through its YAML: the keys build the
// contact, the monitors report it, the energy balance includes the indenter's work, the surface
// is offered as a moving mesh, and bad input is refused with the key named.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <unistd.h>

#include "partita/adapters/register_all.hpp"
#include "partita/run/case_run.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

namespace {

std::unique_ptr<Solver> make_fem(const std::string& yaml, const std::filesystem::path& dir = ".") {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  const auto& e = r.solvers.get("fem");
  SolverContext ctx{"block", config::Node::load_string(yaml).validated(e.spec), dir, dir, 1};
  return e.factory(ctx);
}

const char* kBlock = R"(
mesh: {box: {origin: [0, 0, 0], size: [0.1, 0.1, 0.1], cells: [4, 4, 4]}}
material: {youngs_modulus: 210e9, poisson_ratio: 0.3, density: 7850}
analysis: {type: transient, mass: lumped, integrator: central-difference}
)";

std::string with(const std::string& indenter, const char* base = kBlock) {
  return std::string(base) + "indenters:\n  - " + indenter + "\n";
}

double monitor(const Solver& s, const std::string& name) {
  for (const auto& m : s.monitors())
    if (m.name == name) return m.value;
  FAIL("no monitor " << name);
  return 0.0;
}

}  // namespace

TEST_CASE("fem indenter: a free sphere dropped on a free block, through the YAML",
          "[adapters][fem][contact]") {
  auto s = make_fem(with(
      "{name: ball, shape: sphere, radius: 0.05, position: [0.05, 0.05, 0.15001], face: zmax, "
      "motion: {mass: 2, velocity: [0, 0, -2]}}"));
  // the sphere's surface is offered as a moving mesh that writes its displacement
  const InterfaceMesh* ball = nullptr;
  for (const auto& m : s->meshes())
    if (m.mesh.name() == "ball") ball = &m;
  REQUIRE(ball != nullptr);
  CHECK(ball->mesh.num_triangles() > 100);
  REQUIRE(ball->writes.size() == 1);
  const double dt = s->stable_time_step();
  REQUIRE(dt > 0.0);
  const double e0 = 0.5 * 2.0 * 2.0 * 2.0;
  double peak = 0.0, deepest = 0.0;
  for (int k = 0; k < 3000 && !(monitor(*s, "ball.vz") > 0.0 && monitor(*s, "ball.contact_nodes") == 0.0); ++k) {
    s->advance(dt);
    peak = std::max(peak, monitor(*s, "ball.force_z"));
    deepest = std::max(deepest, monitor(*s, "ball.penetration"));
  }
  CHECK(peak > 0.0);
  CHECK(monitor(*s, "ball.vz") > 0.0);  // rebounded
  // it went on past the point of first contact (the block gives way), then turned back
  CHECK(deepest > 0.0);
  CHECK(monitor(*s, "ball.penetration") < deepest);
  // the structure's energy balance includes the indenter's work (what the sphere lost)
  const double lost = e0 - 0.5 * 2.0 * std::pow(monitor(*s, "ball.vz"), 2);
  CHECK(monitor(*s, "ball.work") == Approx(lost).epsilon(0.01));
  CHECK(std::abs(monitor(*s, "energy_balance")) < 0.01 * e0);
  Eigen::MatrixXd d;
  s->write("ball", "displacement", d);
  CHECK(d.rows() == ball->mesh.size());
  CHECK(d(0, 2) == Approx(monitor(*s, "ball.z") - 0.15001));
}

TEST_CASE("fem indenter: a free body takes the forces on its mesh, a driven one refuses them",
          "[adapters][fem][contact]") {
  // far from the block: only the handed-over forces act. 3 N up in all, spread over the
  // vertices, on 2 kg moving down at 2 m/s: v = -2 + 1.5 t, and its work is the kinetic energy's change
  auto s = make_fem(with(
      "{name: ball, shape: sphere, radius: 0.05, position: [0.05, 0.05, 0.5], face: zmax, "
      "motion: {mass: 2, velocity: [0, 0, -2]}}"));
  const InterfaceMesh* ball = nullptr;
  for (const auto& m : s->meshes())
    if (m.mesh.name() == "ball") ball = &m;
  REQUIRE(ball != nullptr);
  REQUIRE(ball->reads.size() == 1);
  CHECK(ball->reads[0].name == "force");
  Eigen::MatrixXd f = Eigen::MatrixXd::Zero(ball->mesh.size(), 3);
  f.col(2).setConstant(3.0 / static_cast<double>(ball->mesh.size()));
  s->read("ball", "force", f);
  const double dt = s->stable_time_step();
  const int n = 200;
  for (int k = 0; k < n; ++k) s->advance(dt);
  const double t = n * dt, v = -2.0 + 1.5 * t;
  CHECK(monitor(*s, "ball.vz") == Approx(v).epsilon(1e-9));
  CHECK(monitor(*s, "ball.external_force_z") == Approx(3.0).epsilon(1e-12));
  CHECK(monitor(*s, "ball.external_work") == Approx(0.5 * 2.0 * (v * v - 4.0)).epsilon(1e-8));
  CHECK_THROWS_WITH(s->read("ball", "displacement", f), Catch::Contains("reads only 'force' on indenter mesh 'ball'"));

  auto driven = make_fem(with(
      "{name: punch, shape: sphere, radius: 0.05, position: [0.05, 0.05, 0.5], face: zmax, "
      "motion: {velocity: [0, 0, -1]}}"));
  for (const auto& m : driven->meshes())
    if (m.mesh.name() == "punch") CHECK(m.reads.empty());
  CHECK_THROWS_WITH(driven->read("punch", "force", f), Catch::Contains("only when the indenter is free (motion.mass)"));
}

TEST_CASE("fem indenter: bad input names the key and what is allowed", "[adapters][fem][contact]") {
  auto error_of = [](const std::string& yaml) -> std::string {
    try {
      make_fem(yaml);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  CHECK_THAT(error_of(with("{name: a, shape: cube, radius: 1, position: [0, 0, 1], face: zmax, "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("cube") && Catch::Contains("sphere, capsule, plane, surface"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: -1, position: [0, 0, 1], face: zmax, "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("radius"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: top, "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("unknown face 'top'") && Catch::Contains("zmax"));
  // a list of faces: each must exist, none twice; a valid list builds
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: [zmax, top], "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("unknown face 'top'") && Catch::Contains("zmax"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: [zmax, xmax, zmax], "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("'zmax' is named twice"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1.1], face: [zmax, xmax], "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Equals("no error"));
  CHECK_THAT(error_of(with("{name: a, shape: capsule, radius: 1, position: [0, 0, 1], face: zmax, "
                           "motion: {velocity: [0, 0, -1]}}")),
             Catch::Contains("capsule needs 'length'"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: zmax, "
                           "motion: {table: [[0, 0, 0, -1], [0, 0, 0, 0]]}}")),
             Catch::Contains("times must increase"));
  const char* newmark = R"(
mesh: {box: {origin: [0, 0, 0], size: [0.1, 0.1, 0.1], cells: [2, 2, 2]}}
material: {youngs_modulus: 210e9, poisson_ratio: 0.3, density: 7850}
constraints: [{set: zmin, fix: [x, y, z]}]
)";
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: zmax, "
                           "motion: {mass: 1}}",
                           newmark)),
             Catch::Contains("central-difference"));
  CHECK_THAT(error_of(with("{name: a, shape: sphere, radius: 1, position: [0, 0, 1], face: zmax, "
                           "motion: {}}")),
             Catch::Contains("velocity"));
}

TEST_CASE("fem indenter: one that starts inside the structure is refused at set-up, how deep and where",
          "[adapters][fem][contact]") {
  auto error_of = [](const std::string& yaml) -> std::string {
    try {
      make_fem(yaml);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  const auto depth_in = [](const std::string& what) {
    std::smatch m;
    REQUIRE(std::regex_search(what, m, std::regex("lies ([0-9.eE+-]+) m deep")));
    return std::stod(m[1].str());
  };
  // A sphere of 10 mm meant to rest on the block's top (z = 0.1 m) with its centre 10 mm above
  // it, its radius written without the unit: 10 m. The face node nearest the centre,
  // (0.05, 0.05, 0.1), lies 0.01 m from it: 10 - 0.01 = 9.99 m inside.
  {
    const std::string what = error_of(
        with("{name: ball, shape: sphere, radius: 10, position: [0.05, 0.05, 0.11], face: zmax, "
             "motion: {velocity: [0, 0, -1]}}"));
    INFO(what);
    CHECK_THAT(what, Catch::Contains("indenter 'ball' starts inside the structure") &&
                         Catch::Contains("face 'zmax' at (0.05, 0.05, 0.1) m") &&
                         Catch::Contains("radius 10 m") && Catch::Contains("radius: 10 mm"));
    CHECK(depth_in(what) == Approx(9.99).epsilon(1e-3));
  }
  // A capsule along x of radius 0.03 m whose axis runs 0.02 m above the top face, over the whole
  // block: the top nodes on y = 0.05, right under the axis, are 0.03 - 0.02 = 0.01 m inside.
  {
    const std::string what = error_of(
        with("{name: bow, shape: capsule, radius: 0.03, length: 0.2, axis: [1, 0, 0], "
             "position: [0.05, 0.05, 0.12], face: zmax, motion: {velocity: [0, 0, -1]}}"));
    INFO(what);
    CHECK_THAT(what, Catch::Contains("indenter 'bow' starts inside") &&
                         Catch::Contains("capsule (radius 0.03 m, length 0.2 m"));
    CHECK(depth_in(what) == Approx(0.01).epsilon(1e-3));
  }
  // Just touching: the same sphere with its 0.05 m radius on the top face is accepted, and so is
  // a plane on it, pointing down at the block
  CHECK_THAT(error_of(with("{name: ball, shape: sphere, radius: 0.05, position: [0.05, 0.05, 0.15], "
                           "face: zmax, motion: {velocity: [0, 0, -1]}}")),
             Catch::Equals("no error"));
  CHECK_THAT(error_of(with("{name: lid, shape: plane, position: [0, 0, 0.1], normal: [0, 0, -1], "
                           "face: zmax, motion: {velocity: [0, 0, -1]}}")),
             Catch::Equals("no error"));
  // a plane 1 mm below the top face: 0.001 m deep
  const std::string what = error_of(with("{name: lid, shape: plane, position: [0, 0, 0.099], "
                                         "normal: [0, 0, -1], face: zmax, motion: {velocity: [0, 0, -1]}}"));
  INFO(what);
  CHECK_THAT(what, Catch::Contains("half-space") && Catch::Contains("normal points out of the rigid body"));
  CHECK(depth_in(what) == Approx(0.001).epsilon(1e-6));
}

// A closed STL box as a flat punch (shape: surface) pressed by delta into a column on rollers
// (static): uniaxial stress in series with the penalty springs, F = delta / (H/(EA) + h/(f E A)).
TEST_CASE("fem indenter: an STL surface pressed into a column, static", "[adapters][fem][contact]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("partita_stl_punch_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    // the box [-1, 3] x [-1, 3] x [0, 1] cm, wider than the column, above its top (z = 4 cm)
    std::ofstream stl(dir / "punch.stl");
    stl << "solid punch\n";
    const double v[8][3] = {{-1, -1, 0}, {3, -1, 0}, {-1, 3, 0}, {3, 3, 0},
                            {-1, -1, 1}, {3, -1, 1}, {-1, 3, 1}, {3, 3, 1}};
    const int t[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                          {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& tri : t) {
      stl << "facet normal 0 0 0\nouter loop\n";
      for (int k : tri) stl << "vertex " << v[k][0] << " " << v[k][1] << " " << v[k][2] << "\n";
      stl << "endloop\nendfacet\n";
    }
    stl << "endsolid punch\n";
  }
  const double e = 70e9, side = 0.02, height = 0.04, delta = 2e-5, factor = 10.0;
  auto s = make_fem(R"(
mesh: {box: {origin: [0, 0, 0], size: [0.02, 0.02, 0.04], cells: [4, 4, 8]}}
material: {youngs_modulus: 70e9, poisson_ratio: 0.3, density: 2700}
constraints: [{set: zmin, fix: [z]}, {set: xmin, fix: [x]}, {set: ymin, fix: [y]}]
analysis: {type: static}
indenters:
  - {name: punch, shape: surface, stl: punch.stl, scale: 0.01, position: [0, 0, 0.04],
     search_radius: 1.0e-3, face: zmax, penalty: {factor: 10}, motion: {velocity: [0, 0, -2.0e-5]}}
)",
                    dir);
  s->advance(1.0);
  const double area = side * side, h = height / 8;
  const double exact = delta / (height / (e * area) + h / (factor * e * area));
  CHECK(monitor(*s, "punch.force_z") == Approx(exact).epsilon(1e-9));
  CHECK(monitor(*s, "punch.z") == Approx(0.04 - delta));
  CHECK(monitor(*s, "punch.contact_nodes") == 25.0);
  CHECK(monitor(*s, "punch.work") == Approx(0.5 * exact * delta).epsilon(1e-9));
  CHECK(std::abs(monitor(*s, "energy_balance")) < 1e-9 * exact * delta);
  fs::remove_all(dir);
}
