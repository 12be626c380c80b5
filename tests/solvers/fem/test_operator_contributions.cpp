// The FE operator of the nonlinear path as a sum of contributions: a contribution
// beside the material's (here a spring bed, written in the test as a user would) joins the
// static, Newmark and central-difference analyses without a change to them.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <string>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/operator_contribution.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0;

// Linear springs: node n to the ground along x (f_n,x = k u_n,x) and, optionally, a tie spring
// between two nodes along x (f = k (u_a - u_b), -k (u_a - u_b)), which couples nodes that need
// not share an element. W = 1/2 k u^2 summed.
class Springs final : public OperatorContribution {
 public:
  Springs(std::vector<std::size_t> ground, double k, bool tangent = true)
      : ground_(std::move(ground)), k_(k), tangent_(tangent) {}
  void tie(std::size_t a, std::size_t b) { tie_ = {a, b}; }
  std::string_view name() const override { return "springs"; }
  bool has_tangent() const override { return tangent_; }
  std::vector<std::vector<std::size_t>> coupled_node_groups() const override {
    if (tie_.empty()) return {};
    return {tie_};
  }
  void add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
           const BlockAssembler& assembler) override {
    energy_ = 0.0;
    ElementMatrix ke = ElementMatrix::Zero(3, 3);
    ke(0, 0) = k_;
    for (auto n : ground_) {
      // f_n,x += k u_n,x;  K_(n x)(n x) += k
      const double ux = u[3 * static_cast<Eigen::Index>(n)];
      f[3 * static_cast<Eigen::Index>(n)] += k_ * ux;
      energy_ += 0.5 * k_ * ux * ux;
      if (k != nullptr) assembler.add(*k, std::span<const std::size_t>(&n, 1), ke);
    }
    if (!tie_.empty()) {
      const auto a = static_cast<Eigen::Index>(tie_[0]), b = static_cast<Eigen::Index>(tie_[1]);
      const double d = u[3 * a] - u[3 * b];
      f[3 * a] += k_ * d;
      f[3 * b] -= k_ * d;
      energy_ += 0.5 * k_ * d * d;
      if (k != nullptr) {
        ElementMatrix kt = ElementMatrix::Zero(6, 6);
        kt(0, 0) = kt(3, 3) = k_;
        kt(0, 3) = kt(3, 0) = -k_;
        assembler.add(*k, tie_, kt);
      }
    }
  }
  double stored_energy() const override { return energy_; }

 private:
  std::vector<std::size_t> ground_, tie_;
  double k_;
  bool tangent_;
  double energy_ = 0.0;
};

// A bar 1 x 0.1 x 0.1 in uniaxial stress (symmetry planes), elastic (small-strain J2 with a
// yield stress out of reach), 4 x 1 x 1 Hex8.
Model bar() {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.1, 0.1), {4, 1, 1}, ElementType::Hex8}));
  m.set_material_law(
      std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(1e12, 0.0)));
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.fix("zmin", {2});
  return m;
}

}  // namespace

TEST_CASE(
    "operator contributions: springs beside the material carry their share of a static "
    "load, and their energy counts",
    "[fem][nonlinear][contribution]") {
  // end force P on the bar, springs k on each of the 4 end nodes: the bar (EA/L) and the springs
  // (4 k) in parallel, u = P / (EA/L + 4 k) exactly (uniform uniaxial stress)
  const double p = 1e5, area = 0.01, k = 0.5 * kE * area / 1.0;
  Model m = bar();
  m.add_traction("xmax", Vec3(p / area, 0.0, 0.0), [](double t) { return t; });
  StructuralSolver s(std::move(m));
  const auto& end = s.mesh().node_set("xmax");
  REQUIRE(end.size() == 4);
  s.add_contribution(std::make_unique<Springs>(end, k));
  s.step_static(1.0);
  const double u_exact = p / (kE * area / 1.0 + 4.0 * k);
  for (auto n : end) CHECK(s.displacement(n).x() == Approx(u_exact).epsilon(1e-9));
  // stored energy (bar + springs) = external work = P u / 2 (linear, loaded from rest)
  CHECK(s.strain_energy() == Approx(0.5 * p * u_exact).epsilon(1e-9));
  CHECK(std::abs(s.energy_balance()) < 1e-9 * s.external_work());
}

TEST_CASE(
    "operator contributions: the summed tangent equals finite differences, a tie spring "
    "between nodes of different elements included",
    "[fem][nonlinear][contribution]") {
  Model m = test::distorted_box(ElementType::Hex8, 1.0,
                                std::make_shared<NeoHookeLaw>(1e6, 0.3, 1000.0), 7);
  NonlinearOperator op(m);
  auto springs = std::make_unique<Springs>(std::vector<std::size_t>{0, 5}, 3e5);
  // the first and the last node share no element of the 2 x 2 x 2 box
  springs->tie(0, m.mesh().num_nodes() - 1);
  op.add_contribution(std::move(springs));
  const Eigen::VectorXd u = test::large_deformation(m.mesh(), 3);
  CHECK(test::tangent_fd_error(op, u, 1e-6, 4, 11) < 1e-6);
}

TEST_CASE(
    "operator contributions: Newmark conserves the energy of springs and structure, "
    "central difference takes a contribution without a tangent, Newmark names it",
    "[fem][nonlinear][contribution]") {
  // the bar under an end force applied suddenly at t = 0: it oscillates about the static state
  auto run = [](Integrator integrator, bool tangent) {
    Model m = bar();
    m.add_traction("xmax", Vec3(1e7, 0.0, 0.0));
    SolverOptions opt;
    opt.integrator = integrator;
    if (integrator == Integrator::CentralDifference) opt.mass = MassType::Lumped;
    auto s = std::make_unique<StructuralSolver>(std::move(m), opt);
    const auto& end = s->mesh().node_set("xmax");
    s->add_contribution(std::make_unique<Springs>(end, 0.5 * kE * 0.01, tangent));
    const double dt = 0.2 * s->stable_time_step();
    for (int i = 0; i < 200; ++i) s->step(dt);
    return s;
  };
  {
    auto s = run(Integrator::Newmark, true);
    // average acceleration conserves the energy of a linear undamped system: the external work
    // is the kinetic plus the stored energy (bar and springs)
    REQUIRE(s->external_work() > 0.0);
    CHECK(std::abs(s->energy_balance()) < 1e-8 * s->external_work());
  }
  {
    auto s = run(Integrator::CentralDifference, false);
    REQUIRE(s->external_work() > 0.0);
    CHECK(std::abs(s->energy_balance()) < 2e-2 * s->external_work());
  }
  CHECK_THROWS_WITH(run(Integrator::Newmark, false),
                    Catch::Contains("contribution 'springs' has no tangent"));
}
