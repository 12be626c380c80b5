// The DEM participant's default time step (time_step_fraction 0.2 of the Rayleigh
// step) realises the declared restitution to 1 % for 0.1 <= e <= 1, between two spheres and on a
// wall, impacts from 0.01 to 10 m/s.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "dem_adapter_support.hpp"

using namespace partita;
using partita::test::monitor;
namespace fs = std::filesystem;

namespace {

constexpr double E = 1.0e9, NU = 0.3, RHO = 2500.0, R = 1.0e-3;

// Realised restitution of a head-on, frictionless impact at relative speed v, through the
// adapter with its default time step: e = sqrt(kinetic energy after / before) (no friction, no
// gravity, no rotation: all of it is the normal relative motion, or for two equal spheres
// moving symmetrically, the normal motion of each).
double realised(double e, double v, bool wall, const fs::path& dir) {
  fs::create_directories(dir);
  {
    std::ofstream data(dir / "impact.data");
    data << "impact\n\n" << (wall ? 1 : 2) << " atoms\n1 atom types\n\nAtoms\n\n";
    data.precision(17);
    if (wall) {
      data << "1 1 " << 2 * R << " " << RHO << " 0 0 " << R << "\n";
      data << "\nVelocities\n\n1 0 0 " << -v << " 0 0 0\n";
    } else {
      data << "1 1 " << 2 * R << " " << RHO << " " << -R << " 0 0\n";
      data << "2 1 " << 2 * R << " " << RHO << " " << R << " 0 0\n";
      data << "\nVelocities\n\n1 " << 0.5 * v << " 0 0 0 0 0\n2 " << -0.5 * v << " 0 0 0 0 0\n";
    }
  }
  std::ostringstream yaml;
  yaml << "solver: dem\n"
       << "materials: {glass: {youngs_modulus: " << E << ", poisson_ratio: " << NU
       << ", density: " << RHO << "}}\n"
       << "interactions: [{pair: [glass, glass], friction: 0, restitution: " << e << "}]\n"
       << "gravity: [0, 0, 0]\n"
       << "lost_margin: 1\n"
       << "particles: {material: glass, file: impact.data}\n";
  if (wall) yaml << "walls: [{plane: {point: [0, 0, 0], normal: [0, 0, 1]}, material: glass}]\n";
  auto s = test::make_dem(yaml.str(), dir, dir);
  const double ke0 = monitor(*s, "kinetic_energy");
  // Hertz contact time (REFERENCES.md) 2.868 (m*^2/(E*^2 R* v))^(1/5): run three of them
  const double m = RHO * 4.0 / 3.0 * std::numbers::pi * R * R * R;
  const double m_eff = wall ? m : 0.5 * m, r_eff = wall ? R : 0.5 * R;
  const double e_star = E / (2.0 * (1.0 - NU * NU));
  const double t_c = 2.868 * std::pow(m_eff * m_eff / (e_star * e_star * r_eff * v), 0.2);
  const double dt = s->stable_time_step();
  while (s->time() < 3.0 * t_c) s->advance(dt);
  return std::sqrt(monitor(*s, "kinetic_energy") / ke0);
}

}  // namespace

TEST_CASE("dem adapter: the default time step realises the restitution to 1 percent",
          "[adapters][dem][physics]") {
  const fs::path dir = fs::temp_directory_path() / "partita_dem_restitution";
  for (double e : {0.1, 0.3, 0.5, 0.7, 0.9, 1.0}) {
    double worst = 0.0;
    for (double v : {0.01, 0.1, 1.0, 10.0})
      for (bool wall : {false, true}) {
        const double ratio = realised(e, v, wall, dir) / e;
        INFO("e " << e << ", v " << v << " m/s" << (wall ? " on a wall" : ", two spheres")
                  << ": realised " << ratio * e);
        CHECK(std::abs(ratio - 1.0) < 0.01);
        worst = std::max(worst, std::abs(ratio - 1.0));
      }
    WARN("e " << e << ": worst relative error at the default step " << worst);
  }
  fs::remove_all(dir);
}
