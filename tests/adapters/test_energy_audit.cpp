// The interface energy audit (Solver::interface_work) of the native adapters, each against a law
// that does not come from the adapter: the elastic bounce of a sphere off a moving wall (DEM),
// Clapeyron's theorem for a linear elastic body loaded in one step (FEM), and checkpoints.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "../support/adapter_solver.hpp"

using namespace partita;
namespace fs = std::filesystem;

namespace {

std::unique_ptr<Solver> make(const std::string& solver, const std::string& yaml,
                             const fs::path& dir) {
  return test::make_solver(solver, yaml, dir, dir);
}

double monitor(const Solver& s, const std::string& name) { return test::monitor_value(s, name); }

}  // namespace

TEST_CASE("energy audit: a wall driven into a sphere does the work of its elastic bounce",
          "[adapters][dem][energy]") {
  // A sphere at rest, a rigid mesh (infinite mass) driven down onto it at V, restitution 1, no
  // gravity, no friction: the sphere leaves at 2 V (elastic collision with a moving wall), so the
  // wall has done the work 1/2 m (2 V)^2 = 2 m V^2 on it.
  const fs::path dir = fs::temp_directory_path() / "partita_energy_audit_dem";
  fs::create_directories(dir);
  const double d = 0.004, rho = 400.0, z0 = 0.01;
  {
    std::ofstream f(dir / "one.data");
    f << "# one sphere\n\n1 atoms\n1 atom types\n\n0 0.02 xlo xhi\n0 0.02 ylo yhi\n"
         "0 0.02 zlo zhi\n\nAtoms\n\n1 1 "
      << d << " " << rho << " 0.01 0.01 " << z0 << "\n";
  }
  const double gap = 1.0e-4;
  const std::string yaml =
      "solver: dem\n"
      "materials: {glass: {youngs_modulus: 200 MPa, poisson_ratio: 0.23, density: 400},\n"
      "            steel: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}}\n"
      "interactions: [{pair: [glass, glass], restitution: 1.0, friction: 0},\n"
      "               {pair: [glass, steel], restitution: 1.0, friction: 0}]\n"
      "particles: {material: glass, file: one.data}\n"
      "meshes: [{name: plate, rectangle: {origin: [0.005, 0.005, " +
      std::to_string(z0 + 0.5 * d + gap) +
      "], size: [0.01, 0.01], cells: [2, 2]}, material: steel}]\n"
      "gravity: [0, 0, 0]\nenergy_accounting: true\n";
  auto s = make("dem", yaml, dir);
  const Mesh& plate = s->meshes().at(0).mesh;
  REQUIRE(plate.name() == "plate");
  const double V = 0.5;  // [m/s]
  const double dt = 0.5 * s->stable_time_step();
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(plate.size(), 3);
  const double m = rho * std::numbers::pi * d * d * d / 6.0;
  CHECK(s->interface_work("plate").value() == 0.0);
  // drive the wall until it has passed the gap and the contact is over (the sphere, at 2 V, has
  // left the wall, which follows at V)
  double t = 0.0;
  while (t < 4.0 * gap / V) {
    t += dt;
    u.col(2).setConstant(-V * t);
    s->read("plate", "displacement", u);
    s->advance(dt);
  }
  const double ke = monitor(*s, "kinetic_energy");
  INFO("kinetic energy " << ke << " J, 2 m V^2 = " << 2 * m * V * V << " J");
  CHECK(ke == Approx(2.0 * m * V * V).epsilon(0.01));
  // the wall did exactly that work (trapezoidal sum over the steps)
  CHECK(s->interface_work("plate").value() == Approx(ke).epsilon(1e-3));
  // the centres read only "attached", which moves nothing: the work is the vertex mesh's
  CHECK_FALSE(s->interface_work("plate_centres").has_value());
  // the DEM's own accounting: the mesh's work (contact forces times the wall's velocity at the
  // contact points) against the sphere's energy, and the balance
  CHECK(monitor(*s, "plate.work") == Approx(2.0 * m * V * V).epsilon(0.01));
  CHECK(monitor(*s, "plate.work") == Approx(ke).epsilon(1e-3));
  CHECK(monitor(*s, "wall_work") == monitor(*s, "plate.work"));
  CHECK(monitor(*s, "damping_work") == 0.0);  // restitution 1
  CHECK(std::abs(monitor(*s, "energy_balance_error")) < 1e-3);
  CHECK_THROWS_WITH(s->interface_work("plates"), Catch::Contains("no mesh 'plates'"));
}

TEST_CASE("energy audit: a traction applied in one static step does the work 1/2 F u",
          "[adapters][fem][energy]") {
  // Clapeyron: a linear elastic body loaded from zero to F in one step stores U = 1/2 F . u, and
  // the trapezoidal work of the received traction is exactly that.
  const fs::path dir = fs::temp_directory_path() / "partita_energy_audit_fem";
  fs::create_directories(dir);
  const std::string yaml =
      "solver: fem\n"
      "mesh: {box: {origin: [0, 0, 0], size: [0.01, 0.01, 0.02], cells: [2, 2, 4]}}\n"
      "material: {youngs_modulus: 1 GPa, poisson_ratio: 0.3, density: 1000}\n"
      "constraints: [{set: zmin, fix: [x, y, z]}]\n"
      "interfaces: [{name: top, face: zmax}]\n"
      "analysis: {type: static}\n";
  auto s = make("fem", yaml, dir);
  const InterfaceMesh* q = nullptr;
  for (const auto& im : s->meshes())
    if (im.mesh.name() == "top_quadrature") q = &im;
  REQUIRE(q != nullptr);
  Eigen::MatrixXd t(q->mesh.size(), 3);
  t.col(0).setConstant(2.0e5);   // shear [Pa]
  t.col(1).setZero();
  t.col(2).setConstant(-1.0e6);  // compression [Pa]
  CHECK(s->interface_work("top").value() == 0.0);
  s->save_checkpoint();
  s->read("top_quadrature", "traction", t);
  s->advance(1.0e-3);
  const double w = s->interface_work("top").value();
  const double u_strain = monitor(*s, "strain_energy");
  INFO("work " << w << " J, strain energy " << u_strain << " J");
  CHECK(w > 0.0);
  CHECK(w == Approx(u_strain).epsilon(1e-9));
  CHECK(s->interface_work("top_quadrature").value() == w);
  // a second step under the same load: no displacement change, no more work
  s->advance(1.0e-3);
  CHECK(s->interface_work("top").value() == Approx(w).epsilon(1e-12));
  // the checkpoint restores the audit with the state
  s->restore_checkpoint();
  CHECK(s->interface_work("top").value() == 0.0);
}
