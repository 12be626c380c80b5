// Rupture: a failure strain per material, constant or Germanischer Lloyd's
// element-size-dependent eps_f = eps_g + eps_e t / l_e, the first failed element reported, and
// element erosion in explicit analyses with its energy kept in the balance.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/failure_criterion.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/indenter_contact.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/sphere_shape.hpp"
#include "partita/fem/velocity_table.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;

std::shared_ptr<const MaterialLaw> steel(double hardening) {
  return std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, hardening));
}

// A strip L x w x t along x held by its three symmetry planes (x = 0, y = 0, z = 0): uniaxial
// stress, the same in every element.
Mesh strip_mesh(double length, double width, double thickness, int cells) {
  return make_box_mesh(
      {Vec3::Zero(), Vec3(length, width, thickness), {cells, 1, 1}, ElementType::Hex8});
}
void hold_symmetry_planes(Model& m) {
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
}

}  // namespace

TEST_CASE("rupture: the GL failure strain for two element sizes", "[fem][rupture]") {
  // Hex8 cells of 0.1 x 0.1 x 0.01 m and 0.05 x 0.1 x 0.01 m in a 10 mm plate: l_e is the
  // in-plane size sqrt(a_1 a_2) of the two largest extents, 0.1 m and sqrt(0.005) = 0.0707 m
  const auto gl = FailureCriterion::germanischer_lloyd(0.01);
  const Mesh coarse = strip_mesh(1.0, 0.1, 0.01, 10), fine = strip_mesh(1.0, 0.1, 0.01, 20);
  const double l_coarse = failure_element_length(coarse, coarse.element(3));
  const double l_fine = failure_element_length(fine, fine.element(3));
  CHECK(l_coarse == Approx(0.1).epsilon(1e-12));
  CHECK(l_fine == Approx(std::sqrt(0.05 * 0.1)).epsilon(1e-12));
  // eps_f = 0.056 + 0.54 t / l_e
  CHECK(gl.failure_strain(l_coarse) == Approx(0.056 + 0.54 * 0.01 / 0.1).epsilon(1e-12));
  CHECK(gl.failure_strain(l_fine) == Approx(0.056 + 0.54 * 0.01 / std::sqrt(0.005)).epsilon(1e-12));
  CHECK(gl.failure_strain(l_fine) > gl.failure_strain(l_coarse));  // smaller elements: later
  // a tetrahedron: the edge of the regular tetrahedron of its volume
  const Mesh tets = make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Tet4});
  CHECK(failure_element_length(tets, tets.element(0)) ==
        Approx(std::cbrt(6.0 * std::sqrt(2.0) / 6.0)).epsilon(1e-12));
  CHECK_THROWS_WITH(FailureCriterion::germanischer_lloyd(0.0), Catch::Contains("thickness"));
  CHECK_THROWS_WITH(FailureCriterion::constant(-0.1), Catch::Contains("must be > 0"));
}

TEST_CASE("rupture: a strip pulled at a constant rate fails when eps_p reaches eps_f",
          "[fem][rupture]") {
  // u(L, t) = v t: eps = v t / L everywhere; uniaxial J2 with linear hardening H:
  // eps_p = (eps - sigma_y / E) / (1 + H / E), so eps_p = eps_f at
  //   t_f = (L / v) (eps_f (1 + H / E) + sigma_y / E).
  // Quasi-static steps: one to 0.9 t_f (a failure before it would be seen there), then steps of
  // dt = t_f / 500: the failure is seen at the end of the step that crosses t_f.
  const double length = 1.0, v = 1.0, hardening = 1e9;
  for (int cells : {10, 20}) {
    for (bool gl : {false, true}) {
      INFO(cells << " cells, " << (gl ? "GL" : "constant eps_f = 0.08"));
      Model m(strip_mesh(length, 0.1, 0.01, cells));
      m.set_material_law(steel(hardening));
      const auto criterion =
          gl ? FailureCriterion::germanischer_lloyd(0.01) : FailureCriterion::constant(0.08);
      m.set_failure_criterion(criterion);
      hold_symmetry_planes(m);
      m.prescribe("xmax", 0, [v](double t) { return v * t; });
      const double l_e = std::sqrt(length / cells * 0.1);
      const double eps_f = gl ? 0.056 + 0.54 * 0.01 / l_e : 0.08;
      const double t_f = length / v * (eps_f * (1.0 + hardening / kE) + kSy / kE);
      StructuralSolver s(std::move(m));
      const double dt = t_f / 500.0;
      s.step_static(0.9 * t_f);
      while (s.failed_elements() == 0 && s.time() < 2.0 * t_f) s.step_static(dt);
      const auto first = s.first_failure();
      REQUIRE(first.has_value());
      CHECK(first->time >= t_f - 1e-9);
      CHECK(first->time < t_f + dt + 1e-9);
      CHECK(first->time == Approx(t_f).epsilon(0.005));
      CHECK(first->failure_strain == Approx(eps_f).epsilon(1e-12));
      CHECK(first->plastic_strain >= eps_f);
      CHECK(first->region == "all");
      // uniform: every element reaches eps_f within round-off of the same time (the first step
      // that crosses t_f fails some, the next at most all)
      CHECK(s.failed_elements() >= 1);
      CHECK(s.max_equivalent_plastic_strain() == Approx(first->plastic_strain).epsilon(1e-9));
      s.step_static(dt);
      CHECK(s.failed_elements() == static_cast<std::size_t>(cells));
    }
  }
}

TEST_CASE("rupture: erosion removes a failed element, the force drops, the energy balances",
          "[fem][rupture][explicit]") {
  // A strip of three elements along x (0.3 x 0.05 x 0.05 m, symmetry planes), the middle one
  // ("weak") failing at eps_p = 0.02, pulled by a traction ramped over T to 350 MPa (linear
  // hardening H = 2 GPa: the force controls a stable state until failure). Nearly quasi-static
  // (T = 40 ms: 170 elastic periods of the strip, 17 of its plastic mode, sqrt(H / rho)): it fails at sigma = sigma_y + H eps_f = 290 MPa, at
  // t_f = T 290 / 350. Then the middle element leaves: the root's reaction drops to zero (the
  // left element rings about zero), the right element flies off, and
  //   W_ext = W_strain + E_kin + W_plastic + W_eroded
  // still holds (central difference: to O(dt^2); here within 1 % of W_ext).
  const double hardening = 2e9, eps_f = 0.02, area = 0.05 * 0.05, ramp = 0.04;
  const double sigma_max = 350e6;
  auto strip = [&] {
    Mesh mesh =
        make_box_mesh({Vec3::Zero(), Vec3(0.3, 0.05, 0.05), {3, 1, 1}, ElementType::Hex8});
    mesh.assign_region_where("weak", [](const Vec3& c) { return c.x() > 0.1 && c.x() < 0.2; });
    Model m(std::move(mesh));
    m.set_material_law(steel(hardening));
    m.set_failure_criterion("weak", FailureCriterion::constant(eps_f, true));
    hold_symmetry_planes(m);
    m.add_traction("xmax", Vec3(sigma_max, 0.0, 0.0), [ramp](double t) { return t / ramp; });
    return m;
  };
  SolverOptions opt;
  opt.integrator = Integrator::CentralDifference;
  opt.mass = MassType::Lumped;
  StructuralSolver s(strip(), opt);
  const double dt = 0.5 * s.stable_time_step();
  const double t_f = ramp * (kSy + hardening * eps_f) / sigma_max;
  double reaction_before = 0.0;
  SolverState intact;  // a state some steps before the failure
  while (s.failed_elements() == 0 && s.time() < ramp) {
    if (s.time() < 0.95 * t_f) intact = s.save_state();
    s.step(dt);
    if (s.failed_elements() == 0) reaction_before = -s.reaction("xmin").x();
  }
  const auto first = s.first_failure();
  REQUIRE(first.has_value());
  CHECK(first->region == "weak");
  CHECK(first->element == 1);
  CHECK(first->centroid.x() == Approx(0.15));
  CHECK(first->time == Approx(t_f).epsilon(0.02));
  CHECK(reaction_before == Approx((kSy + hardening * eps_f) * area).epsilon(0.02));
  CHECK(s.element_eroded(1));
  CHECK(s.eroded_energy() > 0.0);
  // its nodes are all shared with the intact neighbours: none has left the structure
  for (std::size_t node = 0; node < s.model().mesh().num_nodes(); ++node)
    CHECK(!s.node_detached(node));
  // restart: the failed flags and the eroded energy are part of the committed state
  const SolverState saved = s.save_state();
  const double eroded_at_save = s.eroded_energy();
  // after the failure: the mean reaction over the next 2 ms (about 25 periods of the left
  // element ringing on its own) is ~0 beside the force it carried
  double mean = 0.0;
  int n = 0;
  while (s.time() < first->time + 0.002) {
    s.step(dt);
    mean += -s.reaction("xmin").x();
    ++n;
  }
  mean /= n;
  CHECK(std::abs(mean) < 0.02 * reaction_before);
  CHECK(s.failed_elements() == 1);
  CHECK(std::abs(s.energy_balance()) < 0.01 * s.external_work());
  // energies by part: the regions add up to the totals (the eroded element in neither)
  const RegionEnergies parts = s.region_energies();
  CHECK(parts.kinetic_energy[0] + parts.kinetic_energy[1] ==
        Approx(s.kinetic_energy()).epsilon(1e-12));
  CHECK(parts.strain_energy[0] + parts.strain_energy[1] ==
        Approx(s.strain_energy()).epsilon(1e-12));
  CHECK(parts.plastic_work[0] + parts.plastic_work[1] == Approx(s.plastic_work()).epsilon(1e-12));
  CHECK(parts.plastic_work[1] == 0.0);  // "weak" holds only the eroded element
  // the restored state continues bit for bit
  StructuralSolver r(strip(), opt);
  r.restore_state(saved);
  CHECK(r.failed_elements() == 1);
  CHECK(r.first_failure()->time == first->time);
  CHECK(r.eroded_energy() == eroded_at_save);
  for (int k = 0; k < n; ++k) r.step(dt);
  CHECK(r.displacement() == s.displacement());
  CHECK(r.energy_balance() == s.energy_balance());
  // rolled back to before the failure (an implicit coupling's restore): the element is back in
  // the force and the mass, and it fails again at the same step
  s.restore_state(intact);
  CHECK(s.failed_elements() == 0);
  CHECK(!s.element_eroded(1));
  CHECK(s.eroded_energy() == 0.0);
  while (s.failed_elements() == 0 && s.time() < ramp) s.step(dt);
  CHECK(s.first_failure()->time == first->time);
  CHECK(s.eroded_energy() == eroded_at_save);
}

TEST_CASE("rupture: erosion is refused where it is not supported, with the reason",
          "[fem][rupture]") {
  Model m(strip_mesh(1.0, 0.1, 0.01, 2));
  m.set_material_law(steel(0.0));
  m.set_failure_criterion(FailureCriterion::constant(0.1, true));
  hold_symmetry_planes(m);
  CHECK_THROWS_WITH(StructuralSolver(m), Catch::Contains("central-difference"));
  SolverOptions opt;
  opt.integrator = Integrator::CentralDifference;
  opt.mass = MassType::Lumped;
  opt.rayleigh_beta = 1e-6;
  CHECK_THROWS_WITH(StructuralSolver(m, opt), Catch::Contains("stiffness-proportional"));
  Model linear(strip_mesh(1.0, 0.1, 0.01, 2));
  linear.set_failure_criterion(FailureCriterion::constant(0.1));
  CHECK_THROWS_WITH(StructuralSolver(linear), Catch::Contains("plastic strain"));
}

TEST_CASE("rupture: the nodes of an eroded end element leave the structure",
          "[fem][rupture][explicit]") {
  // The strip of the test above with its last element (x > 0.2, under the pulled face) weak:
  // once it erodes, the 4 nodes of the free end belong to no intact element (node_detached,
  // which takes them off an indenter's contact surface); the 4 at x = 0.2 stay.
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(0.3, 0.05, 0.05), {3, 1, 1}, ElementType::Hex8});
  mesh.assign_region_where("weak", [](const Vec3& c) { return c.x() > 0.2; });
  Model m(std::move(mesh));
  m.set_material_law(steel(2e9));
  m.set_failure_criterion("weak", FailureCriterion::constant(0.02, true));
  hold_symmetry_planes(m);
  m.add_traction("xmax", Vec3(350e6, 0.0, 0.0), [](double t) { return t / 0.04; });
  SolverOptions opt;
  opt.integrator = Integrator::CentralDifference;
  opt.mass = MassType::Lumped;
  StructuralSolver s(std::move(m), opt);
  const double dt = 0.5 * s.stable_time_step();
  for (std::size_t node = 0; node < s.model().mesh().num_nodes(); ++node)
    CHECK(!s.node_detached(node));
  while (s.failed_elements() == 0 && s.time() < 0.04) s.step(dt);
  REQUIRE(s.element_eroded(2));
  int detached = 0, kept = 0;
  for (std::size_t node = 0; node < s.model().mesh().num_nodes(); ++node) {
    const double x = s.model().mesh().node(node).x();
    if (x > 0.25) {
      CHECK(s.node_detached(node));
      ++detached;
    } else {
      CHECK(!s.node_detached(node));
      ++kept;
    }
  }
  CHECK(detached == 4);
  CHECK(kept == 12);
}

// The energy books through a rupture and the ringing after it: a clamped steel plate
// 100 x 100 x 4 mm of 10 x 10 reduced Hex8 (finite-strain J2, eps_f = 0.2, erosion), struck at
// its centre by a rigid sphere (R = 15 mm) driven at 20 m/s: it tears, 16 elements erode, the
// sphere passes through and the petals ring. No other input, so the sphere's work must equal
//   E_kin + E_strain (with the springs) + W_plastic + W_eroded + W_beta,
// W_beta the energy the reduced Hex8's once-a-step update of its enhanced thickness strain
// dissipates (MaterialContribution::enhanced_strain_work()). Measured: within
// 0.33 % of the work at every step once it passes 100 J (7 % of its final 1360 J; 0.14 % at the
// end), and the balance moves by 0.14 J over the 0.94 ms of ringing while W_beta grows by 2.8 J
// (a drift unless W_beta is booked); without summing the penalty stiffness over the intact
// face elements the hole's edge nodes (a quarter of their mass left, all of their stiffness)
// chattered on the sphere and created 70 J (-5.8 %). What is left is the central difference's: its kinetic energy jumps
// when an element's force and mass leave between two steps, and at each touch and release of a
// moving node (IndenterContact); both are of the first order in dt, hence the bound of 0.5 %.
TEST_CASE("rupture: a plate torn by a sphere closes its energy books through erosion and ringing",
          "[fem][rupture][explicit][books]") {
  const double side = 0.1, thickness = 0.004, radius = 0.015, speed = 20.0;
  Model m(make_box_mesh({Vec3::Zero(), Vec3(side, side, thickness), {10, 10, 1}, ElementType::Hex8}));
  m.set_material_law(std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho, HardeningCurve::linear(kSy, 1e9)));
  m.set_hex8_formulation(Hex8Formulation::Reduced);
  m.set_failure_criterion(FailureCriterion::constant(0.2, true));
  for (const char* edge : {"xmin", "xmax", "ymin", "ymax"}) m.fix(edge);
  SolverOptions o;
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  StructuralSolver s(std::move(m), o);
  auto sphere = std::make_shared<SphereShape>(Vec3(side / 2, side / 2, thickness + radius + 1e-4), radius);
  auto contact = std::make_unique<IndenterContact>(
      "sphere", s.model(), "zmax", RigidIndenter(sphere, VelocityTable({{0.0, Vec3(0, 0, -speed)}})));
  IndenterContact& c = *contact;
  c.set_detached([&s](std::size_t node) { return s.node_detached(node); });
  c.set_eroded([&s](std::size_t element) { return s.element_eroded(element); });
  s.add_contribution(std::move(contact));
  const double dt = 0.9 * s.stable_time_step();
  auto balance = [&] { return c.indenter().work() + s.energy_balance(); };
  // the ringing: from the last step with a contact force or a new failure on
  double worst = 0.0, ringing_start = 0.0, balance_start = 0.0, beta_start = 0.0;
  std::size_t failed = 0;
  while (s.time() < 0.0024) {
    s.step(dt);
    if (c.active_nodes() > 0 || s.failed_elements() != failed) {
      failed = s.failed_elements();
      ringing_start = s.time();
      balance_start = balance();
      beta_start = s.enhanced_strain_work();
    }
    if (c.indenter().work() > 100.0) worst = std::max(worst, std::abs(balance()) / c.indenter().work());
  }
  const double drift = balance() - balance_start, beta = s.enhanced_strain_work() - beta_start;
  INFO("failed " << s.failed_elements() << ", work " << c.indenter().work() << " J, ringing from "
                 << ringing_start << " s: the balance moves by " << drift
                 << " J, the enhanced strain dissipates " << beta << " J");
  CHECK(s.failed_elements() >= 8);
  CHECK(s.eroded_energy() > 0.1 * c.indenter().work());
  CHECK(ringing_start < 0.0018);  // the sphere has passed through: 0.6 ms of ringing or more
  CHECK(worst < 0.005);
  CHECK(beta > 0.0);
  CHECK(std::abs(drift) < 0.1 * beta);
  WARN("torn plate: |balance| / work <= " << worst << " once the work passes 100 J; ringing from "
       << ringing_start << " s: balance moves " << drift << " J, enhanced strain work " << beta
       << " J (total " << s.enhanced_strain_work() << " J of " << c.indenter().work() << " J)");
}
