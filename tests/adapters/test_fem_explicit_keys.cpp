// The FEM participant's central-difference keys: mass scaling
// (analysis.mass_scaling_time_step: the added mass as monitors, the step offered raised) and the
// reduced Hex8 (mesh.hex8: reduced), and the errors where they do not apply.
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <string>

#include "partita/adapters/register_all.hpp"
#include "partita/run/case_run.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

namespace {

std::unique_ptr<Solver> make_fem(const std::string& yaml) {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  const auto& e = r.solvers.get("fem");
  SolverContext ctx{"plate", config::Node::load_string(yaml).validated(e.spec), ".", ".", 1};
  return e.factory(ctx);
}

std::string error_of(const std::string& yaml) {
  try {
    make_fem(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

double monitor(const Solver& s, const std::string& name) {
  for (const auto& m : s.monitors())
    if (m.name == name) return m.value;
  FAIL("no monitor " << name);
  return 0.0;
}

// a steel plate 0.2 x 0.2 x 0.002 m, 4 x 4 x 1 cells, clamped edges
std::string plate(const std::string& analysis, const std::string& hex8 = "incompatible-modes") {
  return R"(
mesh: {box: {origin: [0, 0, 0], size: [0.2, 0.2, 0.002], cells: [4, 4, 1]}, hex8: )" +
         hex8 + R"(}
material: {model: j2-plasticity, youngs_modulus: 210e9, poisson_ratio: 0.3, density: 7850,
           yield_stress: 250e6}
constraints: [{set: xmin, fix: [x, y, z]}, {set: xmax, fix: [x, y, z]}]
loads: [{face: zmax, pressure: 1e5, ramp: 1e-3}]
analysis: )" + analysis + "\n";
}

}  // namespace

TEST_CASE("fem keys: mass scaling raises the step offered and reports the added mass",
          "[adapters][fem][mass-scaling]") {
  const std::string cd = "{type: transient, mass: lumped, integrator: central-difference";
  auto plain = make_fem(plate(cd + "}"));
  const double dt = plain->stable_time_step();
  REQUIRE(dt > 0.0);
  std::ostringstream target;
  target.precision(17);
  target << 10.0 * dt / 0.9;  // 10 times the smallest element step dt_min = dt / 0.9
  auto scaled = make_fem(plate(cd + ", mass_scaling_time_step: " + target.str() + "}"));
  // no element's step is left below the target: the step offered is 0.9 x the target = 10 dt
  CHECK(scaled->stable_time_step() == Approx(10.0 * dt).epsilon(1e-9));
  // s_e = (target / dt_e)^2 <= 100, = 100 on the interior columns of cells (half the plate;
  // the cells at the clamped edges have fewer free dofs, so larger dt_e):
  // 99 / 2 <= added mass / the plate's mass <= 99
  const double mass = 7850.0 * 0.2 * 0.2 * 0.002;
  CHECK(monitor(*scaled, "added_mass") >= 49.5 * mass * (1.0 - 1e-9));
  CHECK(monitor(*scaled, "added_mass") <= 99.0 * mass * (1.0 + 1e-9));
  CHECK(monitor(*scaled, "added_mass_percent") ==
        Approx(100.0 * monitor(*scaled, "added_mass") / mass).epsilon(1e-9));
  for (int k = 0; k < 20; ++k) scaled->advance(scaled->stable_time_step());
  CHECK(monitor(*scaled, "kinetic_energy") > 0.0);
  CHECK(std::abs(monitor(*scaled, "energy_balance")) < 1e-2 * monitor(*scaled, "external_work"));
  // elsewhere it is refused with the key named
  CHECK_THAT(error_of(plate("{type: transient, mass_scaling_time_step: 1e-6}")),
             Catch::Contains("mass_scaling_time_step") && Catch::Contains("central-difference"));
}

TEST_CASE("fem keys: hex8 reduced runs central difference and is refused elsewhere",
          "[adapters][fem][reduced]") {
  auto s = make_fem(
      plate("{type: transient, mass: lumped, integrator: central-difference}", "reduced"));
  for (int k = 0; k < 50; ++k) s->advance(s->stable_time_step());
  CHECK(monitor(*s, "max_displacement") > 0.0);
  CHECK(std::abs(monitor(*s, "energy_balance")) < 1e-2 * monitor(*s, "external_work"));
  CHECK_THAT(error_of(plate("{type: transient}", "reduced")),
             Catch::Contains("central-difference") && Catch::Contains("incompatible-modes"));
  CHECK_THAT(error_of(plate("{type: static}", "reduced")), Catch::Contains("central-difference"));
}
