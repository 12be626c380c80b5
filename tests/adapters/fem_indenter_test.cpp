// Rigid indenters of the FEM participant through its YAML (issue 27): the keys build the
// contact, the monitors report it, the energy balance includes the indenter's work, the surface
// is offered as a moving mesh, and bad input is refused with the key named.
#include <catch2/catch.hpp>

#include <string>

#include "partita/adapters/register_all.hpp"
#include "partita/coupling/case_run.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

namespace {

std::unique_ptr<Solver> make_fem(const std::string& yaml) {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  const auto& e = r.solvers.get("fem");
  SolverContext ctx{"block", config::Node::load_string(yaml).validated(e.spec), ".", ".", 1};
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
