// The explicit steps' path of the material's force: without a tangent
// MaterialContribution::add() evaluates all elements in one parallel loop and sums node by node,
// and the laws skip their tangent (MaterialLaw::evaluate_stress). Both must give the force,
// energy and stresses of the tangent path: bit for bit where the same operations run (plain
// and F-bar Hex8), to round-off where the EAS condensation sums its correction in another order.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/material_contribution.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;

std::shared_ptr<const MaterialLaw> law(bool finite) {
  if (finite)
    return std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho, HardeningCurve::linear(kSy, kE / 100));
  return std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kE / 100));
}

// A thin plate (the EAS element's layered rule) under a displacement that bends and stretches
// it well past yield in places.
Model plate(Hex8Formulation formulation, bool finite) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(0.2, 0.15, 0.01), {4, 3, 1}, ElementType::Hex8}),
          Material{kE, kNu, kRho});
  m.set_material_law(law(finite));
  m.set_hex8_formulation(formulation);
  return m;
}

Eigen::VectorXd displacement(const Mesh& mesh) {
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(mesh.num_nodes()));
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n) {
    const Vec3 x = mesh.node(n);
    const auto i = 3 * static_cast<Eigen::Index>(n);
    u[i] = 2e-4 * std::sin(20.0 * x[1]) + 4e-3 * x[0] * (x[2] - 0.005) / 0.01;
    u[i + 1] = 1e-3 * x[0] * x[1] / 0.03;
    u[i + 2] = 2e-3 * std::sin(15.0 * x[0]) * std::cos(10.0 * x[1]);
  }
  return u;
}

struct Result {
  Eigen::VectorXd f;
  double energy = 0.0;
  MatrixX6 stress;
};

Result force(const Model& model, const Eigen::VectorXd& u, bool tangent) {
  MaterialContribution mc(model);
  BlockAssembler assembler(model.mesh());
  Result r;
  r.f = Eigen::VectorXd::Zero(u.size());
  SparseMatrix k;
  if (tangent) k = assembler.make_matrix();
  mc.add(u, r.f, tangent ? &k : nullptr, assembler);
  r.energy = mc.stored_energy();
  r.stress = mc.cauchy_stress();
  return r;
}

}  // namespace

TEST_CASE("explicit force path equals the tangent path", "[fem][explicit][j2]") {
  for (bool finite : {false, true}) {
    for (auto formulation :
         {Hex8Formulation::Full, Hex8Formulation::FBar, Hex8Formulation::IncompatibleModes}) {
      const Model model = plate(formulation, finite);
      const Eigen::VectorXd u = displacement(model.mesh());
      const Result with = force(model, u, true), without = force(model, u, false);
      INFO("finite strain " << finite << ", formulation " << static_cast<int>(formulation));
      REQUIRE(with.f.norm() > 0.0);
      if (formulation == Hex8Formulation::IncompatibleModes) {
        // the condensation's correction K_ua d_alpha summed point by point: round-off
        CHECK((with.f - without.f).norm() <= 1e-12 * with.f.norm());
        CHECK(std::abs(with.energy - without.energy) <= 1e-12 * std::abs(with.energy));
        CHECK((with.stress - without.stress).norm() <= 1e-12 * with.stress.norm());
      } else {
        CHECK((with.f - without.f).cwiseAbs().maxCoeff() == 0.0);
        CHECK(with.energy == without.energy);
        CHECK((with.stress - without.stress).cwiseAbs().maxCoeff() == 0.0);
      }
    }
  }
}

TEST_CASE("evaluate_stress gives the stress and energy and history of evaluate", "[fem][j2]") {
  for (bool finite : {false, true}) {
    const auto l = law(finite);
    std::vector<double> committed(static_cast<std::size_t>(l->state_size()));
    l->initialise_state(committed);
    std::vector<double> trial_a(committed.size()), trial_b(committed.size());
    // beyond yield: 1 % stretch with shear
    Mat3 f = Mat3::Identity();
    f(0, 0) += 0.01;
    f(0, 1) += 0.004;
    f(2, 2) -= 0.003;
    MaterialResponse a, b;
    l->evaluate(f, committed, trial_a, a);
    l->evaluate_stress(f, committed, trial_b, b);
    INFO("finite strain " << finite);
    REQUIRE(l->equivalent_plastic_strain(trial_a) > 0.0);  // past yield: the return map ran
    CHECK((a.stress - b.stress).cwiseAbs().maxCoeff() == 0.0);
    CHECK(a.energy_density == b.energy_density);
    CHECK(trial_a == trial_b);
  }
}
