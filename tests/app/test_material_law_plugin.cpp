// A material law from a plugin (tests/plugins/material_law_plugin.cpp): the stock partita loaded
// with it documents the law as a choice of the FEM's material.model, and a case that names it
// runs with its physics: a one-element bar in uniaxial stress against the stretch worked out by
// hand from W. Plugins whose laws clash with partita's are refused, naming the law.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kPluginDir = PARTITA_TEST_PLUGIN_DIR;

std::string plugin(const std::string& variant) {
  return " --plugin " +
         quote((kPluginDir / ("libpartita_test_law_plugin_" + variant + ".so")).string());
}

const std::string kBar =
    quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/bar_uniaxial.yaml").string());
const std::string kSvk = " --set participants.bar.material.model=saint-venant-kirchhoff";

// The last row of a CSV file as numbers (time first).
std::vector<double> last_row(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<double> v;
  std::stringstream s(last);
  for (std::string cell; std::getline(s, cell, ',');) v.push_back(std::stod(cell));
  return v;
}

}  // namespace

TEST_CASE("material law plugin: the law is a choice of material.model, documented with its keys",
          "[app][plugins][material-law-plugin]") {
  // without the plugin the name is not a law of this partita
  auto r = partita::test::run_partita("check " + kBar + kSvk);
  INFO(r.output);
  CHECK(r.status != 0);
  CHECK(r.output.find("saint-venant-kirchhoff") != std::string::npos);
  CHECK(r.output.find("neo-hooke") != std::string::npos);  // the known laws are listed
  CHECK(partita::test::run_partita("docs fem").output.find("saint-venant-kirchhoff") ==
        std::string::npos);

  // with it, partita docs lists the law among the models, and the case is valid
  r = partita::test::run_partita("docs fem" + plugin("saint_venant_kirchhoff"));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("saint-venant-kirchhoff (finite strain, S = lambda tr(E) I + 2 mu E") !=
        std::string::npos);
  // the keys every law takes stay required; those of the J2 laws say so
  CHECK(r.output.find("youngs_modulus (real, Pa, required)") != std::string::npos);
  CHECK(r.output.find("j2-plasticity, j2-plasticity-finite-strain: initial uniaxial yield") !=
        std::string::npos);
  r = partita::test::run_partita("check " + kBar + kSvk + plugin("saint_venant_kirchhoff"));
  CHECK(r.status == 0);
}

TEST_CASE("material law plugin: a bar of the plugin's law in uniaxial stress, closed form",
          "[app][plugins][material-law-plugin]") {
  // bar_uniaxial.yaml: a unit cube, E = 2.5 MPa, nu = 0.45, a dead traction t = 0.5 MPa on x = 1,
  // the faces x = 0, y = 0, z = 0 held normal. W = lambda/2 (tr E)^2 + mu tr(E^2) gives
  // S = lambda tr(E) I + 2 mu E and P = F S; in uniaxial stress with F = diag(l1, l2, l2),
  // E_i = (l_i^2 - 1) / 2, P_2 = l2 S_2 = 0 gives E_2 = -lambda E_1 / (2 (lambda + mu)), and
  // P_1 = l1 (lambda (E_1 + 2 E_2) + 2 mu E_1) = t fixes l1 (increasing in l1 > 1: bisection).
  const double e = 2.5e6, nu = 0.45, t = 0.5e6;
  const double lambda = e * nu / ((1 + nu) * (1 - 2 * nu)), mu = e / (2 * (1 + nu));
  const auto e2_of = [&](double e1) { return -lambda * e1 / (2 * (lambda + mu)); };
  const auto p1 = [&](double l1) {
    const double e1 = 0.5 * (l1 * l1 - 1);
    return l1 * (lambda * (e1 + 2 * e2_of(e1)) + 2 * mu * e1);
  };
  double lo = 1.0, hi = 3.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) (p1(0.5 * (lo + hi)) > t ? hi : lo) = 0.5 * (lo + hi);
  const double l1 = 0.5 * (lo + hi);
  const double l2 = std::sqrt(1 + 2 * e2_of(0.5 * (l1 * l1 - 1)));
  REQUIRE(l1 > 1.1);  // a large strain, where the law differs from linear elasticity

  const fs::path dir = fs::temp_directory_path() /
                       ("partita_material_law_plugin_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const auto r = partita::test::run_partita("run " + kBar + kSvk + plugin("saint_venant_kirchhoff") +
                                            " --no-plots --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  // tip.csv: time, the mean u_x of the face x = 1 (l1 - 1 at each node), its mean u_y (0 at
  // y = 0 and l2 - 1 at y = 1)
  const auto row = last_row(dir / "tip.csv");
  REQUIRE(row.size() == 3);
  CHECK(row[0] == Approx(1.0));
  CHECK(row[1] == Approx(l1 - 1).epsilon(1e-8));
  CHECK(row[2] == Approx(0.5 * (l2 - 1)).epsilon(1e-8));
  fs::remove_all(dir);
}

TEST_CASE("material law plugin: a law under a built-in law's name, or a key in another unit, is "
          "refused",
          "[app][plugins][material-law-plugin]") {
  auto r = partita::test::run_partita("list" + plugin("builtin_law_name"));
  INFO(r.output);
  CHECK(r.status != 0);
  CHECK(r.output.find("libpartita_test_law_plugin_builtin_law_name.so") != std::string::npos);
  CHECK(r.output.find("material law 'neo-hooke' is already registered") != std::string::npos);

  r = partita::test::run_partita("list" + plugin("other_unit"));
  INFO(r.output);
  CHECK(r.status != 0);
  CHECK(r.output.find("saint-venant-kirchhoff-cgs") != std::string::npos);
  CHECK(r.output.find("'density' is a number in g/cm^3") != std::string::npos);
  CHECK(r.output.find("kg/m^3") != std::string::npos);
}
