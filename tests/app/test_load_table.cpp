// A load table on an FE rod (tests/inputs/fem/rod_release.yaml, a single-solver case): ramped
// on, held, released at once. The free vibration after the release has the rod's first axial
// period T1 = 4 L / c, c = sqrt(E / rho) (fixed-free rod), within 1 %.

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

TEST_CASE("load table: a released rod vibrates with its first axial period", "[app][time-table][slow]") {
  const fs::path dir = fs::temp_directory_path() / ("partita_rod_" + std::to_string(::getpid()));
  const auto r = partita::test::run_command(
      quote(PARTITA_EXECUTABLE) + " run " +
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/rod_release.yaml").string()) +
      " --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / "tip.csv");
  std::string line;
  std::getline(in, line);
  REQUIRE(line == "time [s],rod.tip.displacement_x [m]");
  std::vector<double> t, u;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string a, b;
    std::getline(s, a, ',');
    std::getline(s, b, ',');
    t.push_back(std::stod(a));
    u.push_back(std::stod(b));
  }
  // held: the static elongation F L / (E A) = sigma L / E = 1e6 * 0.5 / 200e9 = 2.5e-6 m
  const std::size_t hold = static_cast<std::size_t>(9.9e-3 / 2.0e-6);
  CHECK(u[hold] == Approx(2.5e-6).epsilon(0.03));
  // zero crossings after the release (t > 10 ms), linearly interpolated
  std::vector<double> crossings;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (t[i - 1] > 10.0e-3 && (u[i - 1] > 0) != (u[i] > 0))
      crossings.push_back(t[i - 1] + (t[i] - t[i - 1]) * u[i - 1] / (u[i - 1] - u[i]));
  REQUIRE(crossings.size() >= 8);
  const double period =
      2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  const double expected = 4.0 * 0.5 / std::sqrt(200.0e9 / 8000.0);  // 4 L / c = 0.4 ms
  CHECK(period == Approx(expected).epsilon(0.01));
  fs::remove_all(dir);
}
