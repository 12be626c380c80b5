// The FEM participant's strain-rate keys (material.cowper_symonds_d, cowper_symonds_q): read
// with their units, in force in transient analyses, and refused with the key named when bad.
#include <catch2/catch.hpp>

#include <string>

#include "../support/adapter_solver.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

namespace {

std::unique_ptr<Solver> make_fem(const std::string& yaml) {
  return test::make_solver("fem", yaml, ".", ".");
}

std::string error_of(const std::string& yaml) {
  try {
    make_fem(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

// a steel plate 0.2 x 0.2 x 0.002 m, 4 x 4 x 1 cells, clamped edges, under a pressure that
// bends it plastically within a millisecond
std::string plate(const std::string& rate_keys, const std::string& model = "j2-plasticity") {
  return R"(
solver: fem
mesh: {box: {origin: [0, 0, 0], size: [0.2, 0.2, 0.002], cells: [4, 4, 1]}}
material: {model: )" +
         model + R"(, youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850,
           yield_stress: 250 MPa)" +
         rate_keys + R"(}
constraints: [{set: xmin, fix: [x, y, z]}, {set: xmax, fix: [x, y, z]}]
loads: [{face: zmax, pressure: 5e6, ramp: 1e-4}]
analysis: {type: transient, mass: lumped, integrator: central-difference}
)";
}

}  // namespace

TEST_CASE(
    "fem strain rate: Cowper-Symonds keys with units lower the plastic strain of a "
    "dynamic bend",
    "[adapters][fem][rate]") {
  for (const std::string model : {"j2-plasticity", "j2-plasticity-finite-strain"}) {
    INFO(model);
    auto plain = make_fem(plate("", model));
    auto rated = make_fem(plate(", cowper_symonds_d: 40.4 /s, cowper_symonds_q: 5", model));
    const double dt = plain->stable_time_step();
    for (int k = 0; k < 3000; ++k) {
      plain->advance(dt);
      rated->advance(dt);
    }
    const double eps_plain = test::monitor_value(*plain, "max_equivalent_plastic_strain");
    const double eps_rated = test::monitor_value(*rated, "max_equivalent_plastic_strain");
    REQUIRE(eps_plain > 0.0);
    // the dynamic flow stress is higher, so the same load strains the plate less plastically
    CHECK(eps_rated < eps_plain);
    CHECK(std::abs(test::monitor_value(*rated, "energy_balance")) <
          1e-2 * test::monitor_value(*rated, "external_work"));
  }
}

TEST_CASE("fem strain rate: bad Cowper-Symonds constants are refused with the key named",
          "[adapters][fem][rate]") {
  CHECK_THAT(error_of(plate(", cowper_symonds_d: -40.4 /s, cowper_symonds_q: 5")),
             Catch::Contains("cowper_symonds_d"));
  CHECK_THAT(error_of(plate(", cowper_symonds_d: 40.4 /s, cowper_symonds_q: 0")),
             Catch::Contains("cowper_symonds_q"));
  CHECK_THAT(error_of(plate(", cowper_symonds_d: 40.4 /s")),
             Catch::Contains("cowper_symonds_d") && Catch::Contains("cowper_symonds_q"));
  CHECK_THAT(error_of(plate(", cowper_symonds_q: 5")),
             Catch::Contains("cowper_symonds_q") && Catch::Contains("cowper_symonds_d"));
  CHECK_THAT(error_of(plate(", cowper_symonds_d: 40.4 MPa, cowper_symonds_q: 5")),
             Catch::Contains("cowper_symonds_d"));
}
