// Inputs that yaml-cpp accepts or that pass a check too early: each gets the project's error with
// the file, line, key and what is allowed (never a raw yaml-cpp exception, never a wrong message).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "partita/interface/config.hpp"

using partita::config::Node;
using partita::config::Spec;

namespace {
std::shared_ptr<Spec> spec() {
  auto m = std::make_shared<Spec>("material", "a material");
  m->real("youngs_modulus", "Young's modulus").unit("Pa").positive().required();
  m->real("length", "a length").unit("m").positive();
  auto s = std::make_shared<Spec>("case", "a test case");
  s->string("case", "name").required();
  s->section("material", "the material", m);
  s->integer("count", "a count");
  s->any("loads", "a list");
  return s;
}
std::string message_of(const std::string& yaml) {
  try {
    Node::load_string(yaml, "case.yaml").validated(spec());
  } catch (const partita::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not a partita::Error: ") + e.what();
  }
  return "";
}
std::string set_message(const std::string& yaml, const std::string& assignment) {
  const auto file = std::filesystem::temp_directory_path() / "partita_config_robustness.yaml";
  std::ofstream(file) << yaml;
  try {
    Node::load_file(file, {assignment});
  } catch (const partita::Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("config: a value infinite after unit conversion is an error", "[interface][config]") {
  const std::string m = message_of("case: c\nmaterial: {youngs_modulus: 1e308 GPa}\n");
  CHECK_THAT(m, Catch::Contains("case.yaml:2:28") &&
                    Catch::Contains("key 'material.youngs_modulus'") &&
                    Catch::Contains("'1e308 GPa' is infinite after conversion to Pa"));
  // the same number without a unit is finite and valid
  CHECK(message_of("case: c\nmaterial: {youngs_modulus: 1e308}\n").empty());
  // a non-zero value that vanishes in SI
  CHECK_THAT(message_of("case: c\nmaterial: {youngs_modulus: 1, length: 1e-320 nm}\n"),
             Catch::Contains("is zero after conversion to m"));
  std::string why;
  CHECK_FALSE(partita::config::parse_quantity("-1e300 GPa", "Pa", &why));
  CHECK_THAT(why, Catch::Contains("infinite"));
  CHECK(partita::config::parse_quantity("0 GPa", "Pa") == 0.0);
  // beyond a double as written
  CHECK_FALSE(partita::config::parse_quantity("1e400", "Pa", &why));
  CHECK_THAT(why, Catch::Contains("out of the range of a real number"));
}

TEST_CASE("config: a sequence or a map used as a key is the project's error",
          "[interface][config]") {
  CHECK_THAT(message_of("case: c\n[a, b]: 1\n"),
             Catch::StartsWith("case.yaml:2:1") &&
                 Catch::Contains("a key must be a plain name, found a sequence used as a key"));
  CHECK_THAT(message_of("case: c\nmaterial:\n  ? {x: 1}\n  : 2\n"),
             Catch::StartsWith("case.yaml:3:5") && Catch::Contains("key 'material'") &&
                 Catch::Contains("found a map used as a key"));
  CHECK_THAT(message_of("case: c\nloads: [{[1]: 2}]\n"),
             Catch::Contains("case.yaml:2:") && Catch::Contains("key 'loads[0]'"));
  // --set values are YAML too
  CHECK_THAT(set_message("case: c\n", "material={[1]: 2}"),
             Catch::Contains("command line (--set)") && Catch::Contains("a key must be a plain"));
}

TEST_CASE("config: an unterminated quoted string is reported where it starts",
          "[interface][config]") {
  CHECK_THAT(message_of("case: c\nmaterial: {youngs_modulus: 1}\nloads: \"abc\ncount: 2\n"),
             Catch::StartsWith("case.yaml:3:8") && Catch::Contains("key 'loads'") &&
                 Catch::Contains("unterminated quoted string") &&
                 Catch::Contains("add the closing \""));
  CHECK_THAT(message_of("case: 'c\ncount: 2\n"),
             Catch::StartsWith("case.yaml:1:7") && Catch::Contains("unterminated quoted string"));
  // closed strings (escaped quotes, '' inside single quotes, over two lines) are fine
  CHECK(message_of("case: \"a \\\" b\"\ncount: 2\n").empty());
  CHECK(message_of("case: 'it''s'\ncount: 2\n").empty());
  CHECK(message_of("case: \"two\n  lines\"\ncount: 2\n").empty());
  // after a byte order mark and multi-byte characters
  CHECK_THAT(message_of("\xEF\xBB\xBF"
                        "case: \"\xC2\xB5\ncount: 2\n"),
             Catch::Contains("unterminated quoted string"));
  CHECK(message_of("\xEF\xBB\xBF"
                   "count: 1\ncase: \"\xC2\xB5\"\n")
            .empty());
}

TEST_CASE("config: aliases cannot make the document endless", "[interface][config]") {
  CHECK_THAT(message_of("case: &a [*a]\n"), Catch::Contains("levels deep"));
  std::string laughs = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 8; ++i) {
    const std::string p = "*a" + std::to_string(i - 1);
    laughs += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + p + ", " + p + ", " +
              p + ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + ", " + p +
              "]\n";
  }
  CHECK_THAT(message_of(laughs), Catch::Contains("more than 1000000 values"));
}

TEST_CASE("config: an integer out of range says so", "[interface][config]") {
  CHECK_THAT(message_of("case: c\ncount: 99999999999999999999\n"),
             Catch::Contains("key 'count'") && Catch::Contains("is out of range"));
}

TEST_CASE("config: --set reaches list elements as key[i], key.i points there",
          "[interface][config]") {
  const std::string yaml = "case: c\nloads: [{p: 1}, {p: 2}]\n";
  CHECK(set_message(yaml, "loads[1].p=3").empty());
  CHECK_THAT(set_message(yaml, "loads.1.p=3"),
             Catch::Contains("'loads' is a list; its element 1 is written 'loads[1]'"));
  CHECK_THAT(set_message(yaml, "loads.1=3"), Catch::Contains("'loads[1]'"));
}

TEST_CASE("config: an unknown key given by --set is reported at the command line",
          "[interface][config]") {
  const auto file = std::filesystem::temp_directory_path() / "partita_config_set_key.yaml";
  std::ofstream(file) << "case: c\nmaterial: {youngs_modulus: 1}\n";
  std::string m;
  try {
    Node::load_file(file, {"material={youngs_modulus: 1, colour: red}"}).validated(spec());
  } catch (const partita::Error& e) {
    m = e.what();
  }
  CHECK_THAT(m, Catch::StartsWith("command line (--set material=...)") &&
                    Catch::Contains("unknown key 'colour'"));
}
