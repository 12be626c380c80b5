// A line probe on a patch-test field (tests/inputs/fem/bar_probe.yaml): a bar in uniaxial stress
// has the exact linear field u = sigma/E (x, -nu y, -nu z), which Hex8 reproduces; the probed
// displacements equal it to 1e-12 (relative to the largest), the stress is sigma_xx = sigma,
// the others zero, and von Mises = sigma, to round-off.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

TEST_CASE("line probe: the exact linear field of a patch test, to 1e-12", "[app][probe]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_probe_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/bar_probe.yaml").string()) +
      " --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / "probes" / "bar_diagonal_000001.csv");
  std::string line;
  std::getline(in, line);
  CHECK(line.rfind("s [m],x [m],y [m],z [m],displacement_x [m]", 0) == 0);
  const double sigma = 10e6, e = 200e9, nu = 0.3;
  const double umax = sigma / e * 0.4;
  int points = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) v.push_back(std::stod(c));
    REQUIRE(v.size() == 14);
    const double x = v[1], y = v[2], z = v[3];
    CHECK(std::abs(v[4] - sigma / e * x) < 1e-12 * umax);
    CHECK(std::abs(v[5] + nu * sigma / e * y) < 1e-12 * umax);
    CHECK(std::abs(v[6] + nu * sigma / e * z) < 1e-12 * umax);
    CHECK(v[7] == Approx(sigma).epsilon(1e-10));
    for (int k = 8; k < 13; ++k) CHECK(std::abs(v[static_cast<std::size_t>(k)]) < 1e-9 * sigma);
    CHECK(v[13] == Approx(sigma).epsilon(1e-10));
    ++points;
  }
  CHECK(points == 17);
  fs::remove_all(dir);
}

// A total-force face load and point monitors on the same patch-test field: F = 100 kN
// over the 0.01 m^2 face is sigma = 10 MPa; the points' displacements are u = sigma/E (x, -nu y,
// -nu z) at the corner and at a point inside an element, to 1e-12; the static reaction is -F.
TEST_CASE("point monitors and a total-force load: the exact patch-test field", "[app][probe]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_points_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/bar_point_force.yaml").string()) +
      " --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / "points.csv");
  std::string line;
  std::getline(in, line);
  CHECK(line ==
        "time [s],bar.tip.displacement_x [m],bar.tip.displacement_y [m],"
        "bar.inside.displacement_x [m],bar.inside.displacement_y [m],"
        "bar.inside.displacement_z [m],bar.static_reaction_x [N]");
  std::string last;
  while (std::getline(in, line)) last = line;
  std::vector<double> v;
  std::stringstream s(last);
  for (std::string c; std::getline(s, c, ',');) v.push_back(std::stod(c));
  REQUIRE(v.size() == 7);
  const double sigma = 100e3 / (0.1 * 0.1), e = 200e9, nu = 0.3;
  const double umax = sigma / e * 0.4;
  CHECK(std::abs(v[1] - sigma / e * 0.4) < 1e-12 * umax);
  CHECK(std::abs(v[2] + nu * sigma / e * 0.1) < 1e-12 * umax);
  CHECK(std::abs(v[3] - sigma / e * 0.21) < 1e-12 * umax);
  CHECK(std::abs(v[4] + nu * sigma / e * 0.047) < 1e-12 * umax);
  CHECK(std::abs(v[5] + nu * sigma / e * 0.033) < 1e-12 * umax);
  CHECK(v[6] == Approx(-100e3).epsilon(1e-12));
  fs::remove_all(dir);
}
