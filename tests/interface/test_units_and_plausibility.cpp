// What a newcomer writes and what partita makes of it: the structures engineer's units, digit
// groups, a bare number meant in GPa, a key written short, a flow map left open.
#include <catch2/catch.hpp>

#include <spdlog/sinks/ostream_sink.h>

#include <sstream>

#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

using partita::config::Node;
using partita::config::parse_quantity;
using partita::config::Spec;

namespace {

std::shared_ptr<Spec> solid_spec() {
  auto s = std::make_shared<Spec>("material", "a solid");
  s->real("youngs_modulus", "Young's modulus")
      .unit("Pa")
      .positive()
      .typical(partita::config::kSolidModulusLow, partita::config::kSolidModulusHigh,
               partita::config::kSolidModulusWhat)
      .required();
  s->real("poisson_ratio", "Poisson's ratio").range(-1.0, 0.5, true).required();
  s->real("density", "density")
      .unit("kg/m^3")
      .positive()
      .typical(partita::config::kSolidDensityLow, partita::config::kSolidDensityHigh,
               partita::config::kSolidDensityWhat)
      .def(7850.0);
  return s;
}

// The warnings the interface logger writes while `f` runs.
template <class F>
std::string warnings_of(F&& f) {
  std::ostringstream out;
  auto logger = partita::log::get("interface");
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
  logger->sinks().push_back(sink);
  const auto level = logger->level();
  logger->set_level(spdlog::level::warn);
  try {
    f();
  } catch (...) {
    logger->sinks().pop_back();
    logger->set_level(level);
    throw;
  }
  logger->sinks().pop_back();
  logger->set_level(level);
  return out.str();
}

std::string error_of(const std::string& yaml, const std::string& name) {
  try {
    Node::load_string(yaml, name);
  } catch (const partita::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("units: the structures engineer's N/mm^2 and the usual equivalents are SI after reading",
          "[interface][config][units]") {
  // 1 N/mm^2 = 1 N / 1e-6 m^2 = 1e6 Pa = 1 MPa
  CHECK(*parse_quantity("235 N/mm^2", "Pa") == Approx(235e6));
  CHECK(*parse_quantity("235 N/mm2", "Pa") == Approx(235e6));
  CHECK(*parse_quantity("235 N/mm\xC2\xB2", "Pa") == Approx(235e6));
  CHECK(*parse_quantity("10 kN/m^2", "Pa") == Approx(1e4));
  CHECK(*parse_quantity("2 bar", "Pa") == Approx(2e5));
  // the mm-t-s system of FE codes: steel 7.85e-9 t/mm^3 = 7850 kg/m^3
  CHECK(*parse_quantity("7.85e-9 t/mm^3", "kg/m^3") == Approx(7850.0));
  CHECK(*parse_quantity("2.5 g/cm^3", "kg/m^3") == Approx(2500.0));
  CHECK(*parse_quantity("36 km/h", "m/s") == Approx(10.0));
  // the SI prefixes still apply to the declared unit, and a wrong unit lists what is allowed
  CHECK(*parse_quantity("210 GPa", "Pa") == Approx(2.1e11));
  std::string why;
  CHECK_FALSE(parse_quantity("210 N/mm", "Pa", &why));
  CHECK_THAT(why, Catch::Contains("unit is Pa") && Catch::Contains("N/mm^2"));
}

TEST_CASE("units: digit groups are refused with the ways to write the number",
          "[interface][config][units]") {
  std::string why;
  // 210,000 is 210000 to some readers and 210.000 to others: neither is guessed
  CHECK_FALSE(parse_quantity("210,000 MPa", "Pa", &why));
  CHECK_THAT(why, Catch::Contains("210000 MPa") && Catch::Contains("210.000 MPa") &&
                      Catch::Contains("decimal"));
  CHECK_FALSE(parse_quantity("0,3", "", &why));
  CHECK_THAT(why, Catch::Contains("0.3"));
  CHECK_FALSE(parse_quantity("210 000 MPa", "Pa", &why));
  CHECK_THAT(why, Catch::Contains("210000 MPa"));
  // a unit that starts with a digit is the unit, not a group: a rate of 40.4 per second
  CHECK(*parse_quantity("40.4 1/s", "1/s") == Approx(40.4));
  CHECK(*parse_quantity("40.4 /s", "1/s") == Approx(40.4));
  CHECK(*parse_quantity("50 1/s", "Hz") == Approx(50.0));
  CHECK_FALSE(parse_quantity("40 400 1/s", "1/s", &why));
  CHECK_THAT(why, Catch::Contains("40400 1/s"));
  // and through a case file, with the key's place
  const auto spec = solid_spec();
  try {
    Node::load_string("youngs_modulus: 210,000 MPa\npoisson_ratio: 0.3\n", "plate.yaml")
        .validated(spec);
    FAIL("210,000 MPa was accepted");
  } catch (const partita::Error& e) {
    CHECK_THAT(std::string(e.what()),
               Catch::Contains("plate.yaml:1:17") && Catch::Contains("youngs_modulus") &&
                   Catch::Contains("210000 MPa"));
  }
}

TEST_CASE("plausibility: a modulus or a density far from any solid is read with a warning that "
          "says what was meant",
          "[interface][config][units]") {
  const auto spec = solid_spec();
  SECTION("210 meant in GPa") {
    double e = 0;
    const std::string w = warnings_of([&] {
      e = Node::load_string("youngs_modulus: 210\npoisson_ratio: 0.3\n", "a.yaml")
              .validated(spec)
              .real("youngs_modulus");
    });
    CHECK(e == 210.0);  // read as written, in SI: a warning, not a guess
    CHECK_THAT(w, Catch::Contains("a.yaml:1:17") && Catch::Contains("youngs_modulus") &&
                      Catch::Contains("210 Pa as read") && Catch::Contains("210 GPa"));
  }
  SECTION("7.85 meant in g/cm^3") {
    const std::string w = warnings_of([&] {
      Node::load_string("youngs_modulus: 210 GPa\npoisson_ratio: 0.3\ndensity: 7.85\n", "b.yaml")
          .validated(spec);
    });
    CHECK_THAT(w, Catch::Contains("density") && Catch::Contains("7.85 g/cm^3"));
  }
  SECTION("values of real solids pass in silence") {
    const std::string w = warnings_of([&] {
      Node::load_string("youngs_modulus: 2.5 MPa\npoisson_ratio: 0.45\ndensity: 1100\n",
                        "rubber.yaml")
          .validated(spec);
      Node::load_string("youngs_modulus: 1.2e12\npoisson_ratio: 0.1\ndensity: 3500\n",
                        "diamond.yaml")
          .validated(spec);
    });
    CHECK(w.empty());
  }
}

TEST_CASE("did you mean: a key written short or long is found by its words", "[interface][config]") {
  const std::vector<std::string> keys = {"youngs_modulus", "poisson_ratio", "density"};
  CHECK(partita::nearest_name("poisson", keys) == "poisson_ratio");
  CHECK(partita::nearest_name("youngs", keys) == "youngs_modulus");
  CHECK(partita::nearest_name("density_kg", keys) == "density");
  CHECK(partita::nearest_name("youngs_modulous", keys) == "youngs_modulus");
  CHECK(partita::nearest_name("ratio", keys).empty());  // not a leading word: no guess
  CHECK(partita::nearest_name("po", keys).empty());
}

TEST_CASE("YAML: a flow map or list left open is reported where it was opened",
          "[interface][config]") {
  // the '{' on line 2 is never closed; the parser gives up on a later line
  const std::string m = error_of(
      "case: x\n"
      "time: {window: 1.0e-3, end: 0.01\n"
      "output: {every: 1.0e-3}\n",
      "open.yaml");
  CHECK_THAT(m, Catch::Contains("open.yaml:2:7") && Catch::Contains("'{' opened here") &&
                    Catch::Contains("'}'"));
  const std::string l = error_of(
      "case: x\n"
      "gravity: [0, 0, -9.81\n"
      "output: 3\n",
      "list.yaml");
  CHECK_THAT(l, Catch::Contains("list.yaml:2:10") && Catch::Contains("'['"));
  // a bracket inside a quoted string or a comment is not one
  const std::string q = error_of(
      "case: \"a { b\"  # and [ here\n"
      "time: {window: 1.0e-3\n"
      "end: 1\n",
      "quoted.yaml");
  CHECK_THAT(q, Catch::Contains("quoted.yaml:2:7"));
}
