// The Cauchy stress the nonlinear path writes for the small-strain laws (linear-elastic and
// j2-plasticity through the NonlinearOperator): under a homogeneous strain it is exactly
// sigma = lambda tr(eps) I + 2 mu eps, with no conversion from a first Piola-Kirchhoff stress
// (which would scale it by about (1 + eps)^-2). A finite-strain law's output is checked against
// its own P F^T / J for comparison.
#include <catch2/catch.hpp>
#include <memory>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0;

// u = eps X: a homogeneous symmetric strain of about 1 % (no rotation, so F - I = eps).
Mat3 homogeneous_strain() {
  Mat3 eps;
  eps << 0.010, 0.002, -0.001, 0.002, -0.004, 0.003, -0.001, 0.003, 0.006;
  return eps;
}

// Largest |sigma_q - sigma_exact| / |sigma_exact| over the quadrature points (Voigt rows).
double worst_stress_error(Model model, const Mat3& f, const Mat3& sigma_exact) {
  NonlinearOperator op(model);
  const Mesh& mesh = model.mesh();
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(mesh.num_nodes())), fi;
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n)
    u.segment<3>(3 * static_cast<Eigen::Index>(n)) = (f - Mat3::Identity()) * mesh.node(n);
  op.evaluate(u, fi, nullptr);
  Eigen::Matrix<double, 1, 6> exact;
  exact << sigma_exact(0, 0), sigma_exact(1, 1), sigma_exact(2, 2), sigma_exact(0, 1),
      sigma_exact(1, 2), sigma_exact(0, 2);
  double worst = 0.0;
  for (Eigen::Index q = 0; q < op.cauchy_stress().rows(); ++q)
    worst = std::max(worst, (op.cauchy_stress().row(q) - exact).norm() / exact.norm());
  return worst;
}

Model box_with(std::shared_ptr<const MaterialLaw> law, Hex8Formulation formulation) {
  Model m = test::distorted_box(ElementType::Hex8, 1.0, std::move(law), 3);
  m.set_hex8_formulation(formulation);
  return m;
}

}  // namespace

TEST_CASE("nonlinear path: the small-strain laws' stress output is their Cauchy stress exactly",
          "[fem][nonlinear][stress]") {
  const Mat3 eps = homogeneous_strain();
  const Mat3 f = Mat3::Identity() + eps;
  const LameConstants lame = lame_constants(kE, kNu);
  // sigma = lambda tr(eps) I + 2 mu eps
  const Mat3 sigma = lame.lambda * eps.trace() * Mat3::Identity() + 2.0 * lame.mu * eps;
  for (auto formulation : {Hex8Formulation::Full, Hex8Formulation::FBar}) {
    INFO("Hex8 formulation " << static_cast<int>(formulation));
    CHECK(worst_stress_error(
              box_with(std::make_shared<LinearElasticLaw>(Material{kE, kNu, kRho}), formulation), f,
              sigma) < 1e-12);
    // yield stress far above the stress: elastic
    CHECK(worst_stress_error(box_with(std::make_shared<J2PlasticityLaw>(
                                          kE, kNu, kRho, HardeningCurve::linear(1e12, 0.0)),
                                      formulation),
                             f, sigma) < 1e-12);
  }
}

TEST_CASE("nonlinear path: a finite-strain law's stress output is P F^T / J",
          "[fem][nonlinear][stress]") {
  const Mat3 f = Mat3::Identity() + homogeneous_strain();
  NeoHookeLaw law(kE, kNu, kRho);
  std::vector<double> none;
  MaterialResponse r;
  law.evaluate(f, none, none, r);
  const Mat3 sigma = r.stress * f.transpose() / f.determinant();
  CHECK(worst_stress_error(
            box_with(std::make_shared<NeoHookeLaw>(kE, kNu, kRho), Hex8Formulation::Full), f,
            sigma) < 1e-12);
}
