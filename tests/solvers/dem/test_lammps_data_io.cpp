// Particle files (LAMMPS data format): what LammpsData::write() writes, read() reads back as the
// same doubles bit for bit (the writer uses the shortest exact decimal form), so a settled bed
// written at the end of one run restarts another with the same particles.
#include <catch2/catch.hpp>

#include "dem_test_helpers.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/lammps_data.hpp"

#include <filesystem>
#include <fstream>

using namespace partita::dem;

TEST_CASE("dem: a written particle file reads back bit for bit", "[dem][io]") {
  System sys = test::single_material(2.0e7, 0.25, 2500.0, 0.5, 0.4);
  const int other = sys.add_material({1.0e8, 0.3, 400.0});
  sys.add_interaction(0, other, {0.4, 0.5, 0.0});
  sys.add_interaction(other, other, {0.4, 0.5, 0.0});
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(
      Eigen::Vector3d::Zero(), Eigen::Vector3d(8e-3, 8e-3, 8e-3), 1.3e-3, 0.7e-3, 0.6, 3);
  sys.add_particles(pk.positions, pk.radii, 0);
  sys.add_particle({4e-3, 4e-3, 12e-3}, 0.9e-3, other, {0.1, -0.2, 0.3}, {1.0, 2.0, -3.0}, 1000);
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(8e-3, 8e-3, 16e-3), 0);
  sys.set_sort_interval(1);  // the ids no longer follow the order
  sys.run(300, 0.2 * sys.rayleigh_time_step());
  // a particle with a mass of its own (a fragment that carries restored mass)
  sys.set_particle_mass(2, 1.37 * sys.particles().mass[2], 1.37 * sys.particles().inertia[2]);

  const auto dir = std::filesystem::path(PARTITA_BINARY_DIR) / "test_output" / "dem";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "settled.data").string();
  const LammpsData written = LammpsData::of(sys.particles(), {2500.0, 400.0});
  written.write(path, "a settled bed\nsecond line dropped");
  CHECK(!std::filesystem::exists(path + ".tmp"));
  const LammpsData d = LammpsData::read(path);

  const Particles& p = sys.particles();
  REQUIRE(d.size() == p.size());
  bool same = true;
  for (std::size_t i = 0; i < p.size(); ++i) {
    same = same && d.id[i] == p.id[i] && d.type[i] == p.material[i] + 1 &&
           d.diameter[i] / 2 == p.radius[i] && d.position[i] == p.position[i] &&
           d.velocity[i] == p.velocity[i] && d.angular_velocity[i] == p.angular_velocity[i] &&
           d.density[i] == written.density[i];
  }
  CHECK(same);
  CHECK(d.density == written.density);
  // densities: the material's where the mass is the material's, else mass / volume
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (i == 2) continue;
    CHECK(d.density[i] == (p.material[i] == 0 ? 2500.0 : 400.0));
  }
  const double r = p.radius[2];
  CHECK(d.density[2] == Approx(1.37 * 2500.0).epsilon(1e-14));
  CHECK(d.density[2] * 4.0 / 3.0 * std::numbers::pi * r * r * r ==
        Approx(p.mass[2]).epsilon(1e-15));
  // the velocities are those of a bed in motion, not zero (else the check above says little)
  double v_max = 0.0;
  for (const auto& v : p.velocity) v_max = std::max(v_max, v.norm());
  CHECK(v_max > 0.0);
  // the box holds every particle
  for (std::size_t i = 0; i < p.size(); ++i) {
    CHECK((d.box_lo.array() <= (p.position[i].array() - p.radius[i])).all());
    CHECK((d.box_hi.array() >= (p.position[i].array() + p.radius[i])).all());
  }
}

TEST_CASE("dem: a particle file that cannot be written is an error", "[dem][io]") {
  const LammpsData d;
  CHECK_THROWS_AS(d.write("/nonexistent/dir/bed.data", "x"), Error);
}

TEST_CASE("dem: a partial Velocities section is refused with the file, line and counts",
          "[dem][io]") {
  const auto dir = std::filesystem::path(PARTITA_BINARY_DIR) / "test_output" / "dem";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "partial_velocities.data").string();
  auto write = [&](const std::string& velocities) {
    std::ofstream f(path);
    f << "three atoms\n\n3 atoms\n1 atom types\n\nAtoms\n\n"
         "1 1 0.002 2500 0 0 0.01\n2 1 0.002 2500 0.01 0 0.01\n3 1 0.002 2500 0.02 0 0.01\n"
      << velocities;
  };
  // two lines for three atoms: refused (LAMMPS refuses it too), naming the section's line
  write("\nVelocities\n\n1 0 0 -1 0 0 0\n3 0 0 -1 0 0 0\n");
  try {
    (void)LammpsData::read(path);
    FAIL("a partial Velocities section was accepted");
  } catch (const Error& e) {
    const std::string m = e.what();
    INFO(m);
    CHECK(m.find(path + ":12:") != std::string::npos);  // the line of the section's heading
    CHECK(m.find("2 lines for 3 atoms") != std::string::npos);
    CHECK(m.find("atom id 2 has none") != std::string::npos);
  }
  // a line given twice is not a line for each atom
  write("\nVelocities\n\n1 0 0 -1 0 0 0\n1 0 0 -1 0 0 0\n3 0 0 -1 0 0 0\n");
  CHECK_THROWS_WITH(LammpsData::read(path), Catch::Contains("second velocity line for atom id 1"));
  // every atom: accepted; no section at all: every atom at rest
  write("\nVelocities\n\n3 0 0 -3 0 0 0\n1 0 0 -1 0 0 0\n2 0 0 -2 0 0 0\n");
  const LammpsData full = LammpsData::read(path);
  REQUIRE(full.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) CHECK(full.velocity[i].z() == -static_cast<double>(i + 1));
  write("");
  const LammpsData rest = LammpsData::read(path);
  REQUIRE(rest.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) CHECK(rest.velocity[i].norm() == 0.0);
}

TEST_CASE("dem: a particle file's numbers are read whole and finite, with a trailing comment",
          "[dem][io][errors]") {
  const auto dir = std::filesystem::path(PARTITA_BINARY_DIR) / "test_output" / "dem";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "fields.data").string();
  auto write = [&](const std::string& atom, const std::string& velocity) {
    std::ofstream f(path);
    f << "one atom\n\n1 atoms\n1 atom types\n\nAtoms # sphere\n\n" << atom
      << "\n\nVelocities\n\n" << velocity << "\n";
  };
  // as LAMMPS writes them: exponents, a '+' sign, tabs, a comment after the values
  write("7 1 2.5e-3 +400 -1.5E-2\t0 0.01  # a comment", "7 0 0 -1e+0 0 0 0.5");
  const LammpsData d = LammpsData::read(path);
  REQUIRE(d.size() == 1);
  CHECK(d.id[0] == 7);
  CHECK(d.diameter[0] == 2.5e-3);
  CHECK(d.density[0] == 400.0);
  CHECK(d.position[0].x() == -1.5e-2);
  CHECK(d.position[0].z() == 0.01);
  CHECK(d.velocity[0].z() == -1.0);
  CHECK(d.angular_velocity[0].z() == 0.5);
  // a number run into letters, an infinite or missing one: refused with the file and line
  const auto refused = [&](const std::string& atom, const std::string& velocity,
                           const std::string& what) {
    write(atom, velocity);
    try {
      (void)LammpsData::read(path);
      FAIL("accepted: '" << atom << "' / '" << velocity << "'");
    } catch (const Error& e) {
      const std::string m = e.what();
      INFO(m);
      CHECK(m.find(path + ":") != std::string::npos);
      CHECK(m.find(what) != std::string::npos);
    }
  };
  refused("7 1 2.5e-3 400 0 0 0.01abc", "7 0 0 0 0 0 0", "expected 'id type diameter density x y z'");
  refused("7 1 2.5e-3 400 inf 0 0.01", "7 0 0 0 0 0 0", "finite numbers");
  refused("7 1 2.5e-3 400 0 0", "7 0 0 0 0 0 0", "expected 'id type diameter density x y z'");
  refused("7.5 1 2.5e-3 400 0 0 0.01", "7 0 0 0 0 0 0", "expected 'id type");
  refused("7 1 2.5e-3 400 0 0 0.01", "7 0 0 nan 0 0 0", "expected 'id vx vy vz wx wy wz'");
}
