#include <catch2/catch.hpp>

#include "partita/interface/config.hpp"

using partita::config::Node;
using partita::config::Spec;

namespace {
std::shared_ptr<Spec> material_spec() {
  auto s = std::make_shared<Spec>("material", "An isotropic elastic material");
  s->real("youngs_modulus", "Young's modulus").unit("Pa").positive().required();
  s->real("poisson_ratio", "Poisson's ratio").range(-1.0, 0.5, true).required();
  s->real("density", "Mass density").unit("kg/m^3").positive().def(1000.0);
  return s;
}
std::shared_ptr<Spec> case_spec() {
  auto s = std::make_shared<Spec>("case", "A test case");
  s->string("case", "name").required();
  s->section("material", "the material", material_spec()).required();
  s->choice("scheme", "coupling scheme", {"explicit-serial", "implicit-serial"})
      .def("explicit-serial");
  s->reals("gravity", "gravity vector").unit("m/s^2").size(3).def(std::vector<double>{0, 0, -9.81});
  s->integer("substeps", "substeps per window").min(1).def(1);
  return s;
}
std::string message_of(const std::string& yaml) {
  try {
    Node::load_string(yaml, "case.yaml").validated(case_spec());
  } catch (const partita::Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("config: valid input, defaults and units", "[interface][config]") {
  const Node n = Node::load_string(
                     "case: demo\n"
                     "material:\n"
                     "  youngs_modulus: 200 MPa\n"
                     "  poisson_ratio: 0.23\n"
                     "substeps: 4\n",
                     "case.yaml")
                     .validated(case_spec());
  CHECK(n.string("case") == "demo");
  CHECK(n["material"].real("youngs_modulus") == 2.0e8);
  CHECK(n["material"].real("density") == 1000.0);  // default
  CHECK(n.string("scheme") == "explicit-serial");  // default
  CHECK(n.integer("substeps") == 4);
  CHECK(n.vec3("gravity").z() == -9.81);
  CHECK_FALSE(n["material"].has("density"));
}

TEST_CASE("config: units are converted explicitly to SI", "[interface][config]") {
  using partita::config::parse_quantity;
  CHECK(*parse_quantity("10 kPa", "Pa") == Approx(1.0e4));
  CHECK(*parse_quantity("2 mm", "m") == Approx(2.0e-3));
  CHECK(*parse_quantity("250 GPa", "Pa") == Approx(2.5e11));
  CHECK(*parse_quantity("3 cm^2", "m^2") == Approx(3.0e-4));
  CHECK(*parse_quantity("7.85 g/cm^3", "kg/m^3") == Approx(7850.0));  // an equivalent unit
  CHECK(*parse_quantity("400 kg/m^3", "kg/m^3") == 400.0);
  CHECK(*parse_quantity("5 g", "kg") == Approx(5e-3));
  std::string why;
  CHECK_FALSE(parse_quantity("10 kN", "Pa", &why));
  CHECK(why.find("unit is Pa") != std::string::npos);
  CHECK_FALSE(parse_quantity("1.5", "", &why).value_or(0) != 1.5);
  CHECK_FALSE(parse_quantity("abc", "Pa"));
  CHECK_FALSE(parse_quantity("nan", "Pa"));
}

TEST_CASE("config: errors name file, line, column, key path, value and what is allowed",
          "[interface][config]") {
  SECTION("out of range") {
    const std::string m =
        message_of("case: x\nmaterial:\n  youngs_modulus: 1e9\n  poisson_ratio: 0.6\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:4:18") && Catch::Contains("material.poisson_ratio") &&
                      Catch::Contains("0.6") && Catch::Contains("-1 < value < 0.5"));
  }
  SECTION("negative value of a positive quantity") {
    const std::string m =
        message_of("case: x\nmaterial:\n  youngs_modulus: -5\n  poisson_ratio: 0.3\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:3:19") && Catch::Contains("material.youngs_modulus") &&
                      Catch::Contains("0 < value"));
  }
  SECTION("unknown key with suggestion") {
    const std::string m = message_of(
        "case: x\nmaterial:\n  youngs_modulus: 1e9\n  poisson_ratio: 0.3\n  densty: 5\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:5:3") && Catch::Contains("material.densty") &&
                      Catch::Contains("unknown key 'densty'") &&
                      Catch::Contains("did you mean 'density'?"));
  }
  SECTION("missing required key") {
    const std::string m = message_of("case: x\nmaterial:\n  youngs_modulus: 1e9\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:3:3") && Catch::Contains("key 'material'") &&
                      Catch::Contains("missing required key 'poisson_ratio'"));
  }
  SECTION("wrong type") {
    const std::string m =
        message_of("case: x\nmaterial:\n  youngs_modulus: [1, 2]\n  poisson_ratio: 0.3\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:3:19") && Catch::Contains("expected a real number") &&
                      Catch::Contains("found a sequence"));
  }
  SECTION("unknown choice") {
    const std::string m = message_of(
        "case: x\nmaterial: {youngs_modulus: 1e9, poisson_ratio: 0.3}\nscheme: explicit-seral\n");
    CHECK_THAT(m, Catch::Contains("case.yaml:3:9") && Catch::Contains("key 'scheme'") &&
                      Catch::Contains("explicit-serial, implicit-serial") &&
                      Catch::Contains("did you mean 'explicit-serial'?"));
  }
  SECTION("wrong vector length and integer expected") {
    CHECK_THAT(
        message_of(
            "case: x\nmaterial: {youngs_modulus: 1e9, poisson_ratio: 0.3}\ngravity: [0, -9.81]\n"),
        Catch::Contains("expected 3 values"));
    CHECK_THAT(
        message_of("case: x\nmaterial: {youngs_modulus: 1e9, poisson_ratio: 0.3}\nsubsteps: 2.5\n"),
        Catch::Contains("expected an integer") && Catch::Contains("'2.5'"));
    CHECK_THAT(
        message_of("case: x\nmaterial: {youngs_modulus: 1e9, poisson_ratio: 0.3}\nsubsteps: 0\n"),
        Catch::Contains("1 <= value"));
  }
  SECTION("duplicate key") {
    CHECK_THAT(
        message_of("case: x\ncase: y\nmaterial: {youngs_modulus: 1e9, poisson_ratio: 0.3}\n"),
        Catch::Contains("duplicate key 'case'") && Catch::Contains("case.yaml:2:1"));
  }
  SECTION("YAML syntax error") {
    CHECK_THAT(message_of("case: x\nmaterial: {youngs_modulus: 1e9\n"),
               Catch::Contains("case.yaml:") && Catch::Contains("YAML syntax error"));
  }
}

TEST_CASE("config: docs come from the declarations", "[interface][config]") {
  const std::string d = case_spec()->docs();
  CHECK_THAT(d, Catch::Contains("youngs_modulus (real, Pa, required)") &&
                    Catch::Contains("poisson_ratio") && Catch::Contains("-1 < value < 0.5") &&
                    Catch::Contains("default explicit-serial"));
  // defaults in their shortest exact form, not with 17 digits
  CHECK_THAT(d, Catch::Contains("default [0, 0, -9.81]") && Catch::Contains("default 1000"));
  CHECK_THAT(d, !Catch::Contains("9.8100000"));
}
