// The reduced Hex8 (Hex8Formulation::Reduced, the explicit plate element): one point in
// the plane, a line of points through the thickness, hourglass stabilisation, one enhanced
// thickness strain updated once per step. Central difference only.
#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;

std::shared_ptr<const MaterialLaw> elastic() {
  return std::make_shared<LinearElasticLaw>(Material{kE, kNu, kRho});
}

SolverOptions explicit_options() {
  SolverOptions o;
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  return o;
}

// The element stiffness of a small-strain law at rest, column by column: f(e_i) (the force is
// linear in u there, f(0) = 0); beta stays at its committed 0.
Eigen::MatrixXd force_matrix(Model m) {
  NonlinearOperator op(m);
  const auto n = static_cast<Eigen::Index>(3 * m.mesh().num_nodes());
  Eigen::MatrixXd k(n, n);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), f;
  for (Eigen::Index i = 0; i < n; ++i) {
    u[i] = 1e-6;
    op.evaluate(u, f, nullptr);
    k.col(i) = f / 1e-6;
    u[i] = 0.0;
  }
  return k;
}

// Plate strip L x b x h, n x 1 x 1 reduced Hex8, root held (u_x, u_z on the root face, u_y on
// its edge y = 0: free to contract, as beam theory assumes), the tip face's u_z prescribed by
// `tip` (a function of time).
Model strip(std::shared_ptr<const MaterialLaw> law, double l, double b, double h, int n,
            std::function<double(double)> tip) {
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(l, b, h), {n, 1, 1}, ElementType::Hex8});
  mesh.add_node_set_where("root_edge",
                          [](const Vec3& x) { return x.x() < 1e-12 && x.y() < 1e-12; });
  Model m(std::move(mesh));
  m.set_material_law(std::move(law));
  m.set_hex8_formulation(Hex8Formulation::Reduced);
  m.fix("xmin", {0, 2});
  m.fix("root_edge", {1});
  m.prescribe("xmax", 2, std::move(tip));
  return m;
}

// Tip displacement ramped smoothly (1 - cos) to w over `ramp`, then held.
std::function<double(double)> smooth_ramp(double w, double ramp) {
  return [w, ramp](double t) {
    return t < ramp ? 0.5 * w * (1.0 - std::cos(M_PI * t / ramp)) : w;
  };
}

// Runs the strip to `end` (with mass-proportional damping the structure settles where the tip
// is held) and returns the force the tip carries (the reaction on the tip face, |z|).
double settled_tip_force(StructuralSolver& s, double end) {
  const double dt = 0.9 * s.stable_time_step();
  while (s.time() < end) s.step(dt);
  return std::abs(s.reaction("xmax").z());
}

}  // namespace

TEST_CASE("reduced Hex8: patch test, a homogeneous deformation of a distorted mesh is exact",
          "[fem][explicit][reduced]") {
  Mat3 f0;
  f0 << 1.10, 0.05, 0.0, 0.02, 0.95, 0.03, 0.01, 0.0, 1.05;
  for (auto law : std::vector<std::shared_ptr<const MaterialLaw>>{
           std::make_shared<NeoHookeLaw>(kE, kNu, kRho),
           std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(1e12, 0.0))}) {
    INFO(law->name());
    // thick (2 points through) and thin (6 points through) distorted elements
    for (double depth : {1.0, 0.2}) {
      Model m = test::distorted_box(ElementType::Hex8, depth, law, 5);
      m.set_hex8_formulation(Hex8Formulation::Reduced);
      // the law's stress at every point, the interior node in equilibrium (no hourglass force
      // either: gamma is orthogonal to every linear field)
      test::check_homogeneous_patch(m, f0, *law);
    }
  }
}

TEST_CASE("reduced Hex8: a single element's stiffness has the 6 rigid-body modes and no other "
          "zero-energy mode",
          "[fem][explicit][reduced]") {
  // a cube, a thin plate element and a distorted thin one
  for (int shape = 0; shape < 3; ++shape) {
    INFO("shape " << shape);
    const double depth = shape == 0 ? 1.0 : 0.1;
    Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.8, depth), {1, 1, 1}, ElementType::Hex8});
    if (shape == 2) {
      mesh.set_node(6, mesh.node(6) + Vec3(0.15, -0.1, 0.02));
      mesh.set_node(1, mesh.node(1) + Vec3(0.05, 0.1, -0.01));
    }
    Model m(std::move(mesh));
    m.set_material_law(elastic());
    m.set_hex8_formulation(Hex8Formulation::Reduced);
    const Eigen::MatrixXd k = force_matrix(m);
    // a potential's Hessian: symmetric
    CHECK((k - k.transpose()).norm() < 1e-9 * k.norm());
    const Eigen::VectorXd lambda =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (k + k.transpose()),
                                                       Eigen::EigenvaluesOnly)
            .eigenvalues();
    INFO("eigenvalues / largest: " << (lambda / lambda.maxCoeff()).transpose());
    CHECK(lambda.minCoeff() > -1e-9 * lambda.maxCoeff());
    CHECK(lambda[5] < 1e-9 * lambda.maxCoeff());   // 6 rigid-body modes
    CHECK(lambda[6] > 1e-6 * lambda.maxCoeff());   // and nothing else without energy
  }
}

TEST_CASE("reduced Hex8: a plate strip L/h = 100, one element through the thickness, bends as "
          "Euler-Bernoulli",
          "[fem][explicit][reduced][slow]") {
  // L = 1 m, b = 50 mm, h = 10 mm, 10 x 1 x 1 (each 100 x 50 x 10 mm: 6 points through); the
  // tip is pushed w = 5 mm over 0.12 s (one period of the first bending mode) and held while
  // mass-proportional damping (about critical in that mode) lets the strip settle
  constexpr double l = 1.0, b = 0.05, h = 0.01, w = 0.005;
  const double k_eb = 3.0 * kE * (b * h * h * h / 12.0) / (l * l * l);
  SolverOptions o = explicit_options();
  o.rayleigh_alpha = 100.0;
  StructuralSolver s(strip(elastic(), l, b, h, 10, smooth_ramp(w, 0.12)), o);
  const double force = settled_tip_force(s, 0.25);
  INFO("tip force " << force << " N, Euler-Bernoulli " << k_eb * w << " N, " << s.step_count()
                    << " steps");
  WARN("reduced Hex8 strip: tip stiffness / Euler-Bernoulli = " << force / (k_eb * w));
  CHECK(force / (k_eb * w) == Approx(1.0).margin(0.03));
}

TEST_CASE("reduced Hex8: the perfectly plastic strip carries its limit load within 5 %",
          "[fem][explicit][reduced][limit]") {
  // L/h = 25 (L = 0.25 m, b = 50 mm, h = 10 mm, 20 x 1 x 1): the limit load does not depend on
  // the slenderness, and the explicit run is (L/h)^2 shorter than at L/h = 100. The strip bends
  // cylindrically at its hinge (its width keeps eps_yy = 0 there), so M_p is the plane-strain
  // one, (2 / sqrt 3) sigma_y b h^2 / 4, and P_L = M_p / L. The tip is pushed to 4 times the
  // elastic deflection at P_L and held, damped: the hinge stays at its plastic moment.
  constexpr double l = 0.25, b = 0.05, h = 0.01;
  const double limit = 2.0 / std::sqrt(3.0) * kSy * b * h * h / (4.0 * l);
  const double w_y = limit * l * l * l / (3.0 * kE * b * h * h * h / 12.0);
  auto j2 = std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0));
  SolverOptions o = explicit_options();
  o.rayleigh_alpha = 1000.0;
  StructuralSolver s(strip(j2, l, b, h, 20, smooth_ramp(4.0 * w_y, 0.015)), o);
  const double force = settled_tip_force(s, 0.035);
  INFO("tip force " << force << " N, P_L " << limit << " N, " << s.step_count() << " steps");
  REQUIRE(s.max_equivalent_plastic_strain() > 0.0);
  WARN("reduced Hex8 strip: tip force held / plane-strain P_L = " << force / limit);
  CHECK(force / limit == Approx(1.0).margin(0.05));
}

TEST_CASE("reduced Hex8: energy balance of a thin strip struck by a load, elastic and J2",
          "[fem][explicit][reduced]") {
  for (auto law : std::vector<std::shared_ptr<const MaterialLaw>>{
           elastic(),
           std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0))}) {
    INFO(law->name());
    Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(0.25, 0.05, 0.01), {10, 1, 1}, ElementType::Hex8});
    Model m(std::move(mesh));
    m.set_material_law(law);
    m.set_hex8_formulation(Hex8Formulation::Reduced);
    m.fix("xmin");
    // suddenly applied: 3 kN, about twice the J2 strip's limit load
    m.add_traction("xmax", Vec3(0.0, 0.0, -6e6));
    StructuralSolver s(std::move(m), explicit_options());
    const double dt = 0.9 * s.stable_time_step();
    for (int i = 0; i < 4000; ++i) s.step(dt);
    REQUIRE(s.external_work() > 0.0);
    INFO("balance " << s.energy_balance() << " J of external work " << s.external_work()
                    << " J, plastic " << s.plastic_work() << " J");
    CHECK(std::abs(s.energy_balance()) < 1e-2 * s.external_work());
  }
}

TEST_CASE("reduced Hex8: refused outside central difference", "[fem][explicit][reduced]") {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.1, 0.1), {2, 1, 1}, ElementType::Hex8}),
          Material{kE, kNu, kRho});
  m.set_hex8_formulation(Hex8Formulation::Reduced);
  CHECK_THROWS_WITH(StructuralSolver(m), Catch::Contains("central-difference"));
  SolverOptions o = explicit_options();
  o.rayleigh_beta = 1e-6;
  CHECK_THROWS_WITH(StructuralSolver(m, o), Catch::Contains("rayleigh.alpha"));
}

TEST_CASE("reduced Hex8: a restart continues bit-identically (the enhanced strain is history)",
          "[fem][explicit][reduced]") {
  auto make = [] {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(0.25, 0.05, 0.01), {10, 1, 1}, ElementType::Hex8}));
    m.set_material_law(
        std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, 0.0)));
    m.set_hex8_formulation(Hex8Formulation::Reduced);
    m.fix("xmin");
    m.add_traction("xmax", Vec3(0.0, 0.0, -6e6));
    return StructuralSolver(std::move(m), explicit_options());
  };
  StructuralSolver a = make(), b = make();
  const double dt = 0.9 * a.stable_time_step();
  for (int i = 0; i < 300; ++i) a.step(dt);
  b.restore_state(a.save_state());
  for (int i = 0; i < 300; ++i) {
    a.step(dt);
    b.step(dt);
  }
  REQUIRE(a.max_equivalent_plastic_strain() > 0.0);
  CHECK((a.displacement().array() == b.displacement().array()).all());
  CHECK(a.save_state().material_state == b.save_state().material_state);
}
