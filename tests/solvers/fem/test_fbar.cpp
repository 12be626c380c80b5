// F-bar Hex8 of the nonlinear path: a homogeneous deformation is left exactly as the law gives
// it (patch test, distorted elements included), the tangent is the derivative of the internal
// force and symmetric for hyperelastic laws, and the linear path refuses it. Its effect on
// locking is in test_cook_membrane.cpp.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <memory>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/decoupled_neo_hooke_law.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/nonlinear_operator.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 2.5e6, kRho = 1100.0;

Model fbar_box(std::shared_ptr<const MaterialLaw> law, unsigned long long seed) {
  Model m = test::distorted_box(ElementType::Hex8, 0.5, std::move(law), seed);
  m.set_hex8_formulation(Hex8Formulation::FBar);
  return m;
}

}  // namespace

TEST_CASE("f-bar hex8: a homogeneous deformation gives exactly the law's stress",
          "[fem][nonlinear][fbar]") {
  // u = (F0 - I) X on a distorted mesh: F = F0 at every point, J_bar = J, F_bar = F. The
  // Cauchy stress at every point must be the law's sigma(F0), the energy W(F0) V, and the
  // internal force that of the plain element (the F-bar correction integrates to zero).
  Mat3 f0;
  f0 << 1.3, 0.2, 0.0, 0.0, 0.9, 0.1, 0.05, 0.0, 1.1;
  auto law = std::make_shared<NeoHookeLaw>(kE, 0.45, kRho);
  Model fbar = fbar_box(law, 5);
  Model plain = test::distorted_box(ElementType::Hex8, 0.5, law, 5);
  plain.set_hex8_formulation(Hex8Formulation::Full);
  NonlinearOperator op(fbar), op_plain(plain);
  REQUIRE(op.fbar_hex8());
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(fbar.mesh().num_nodes()));
  for (std::size_t n = 0; n < fbar.mesh().num_nodes(); ++n)
    u.segment<3>(3 * static_cast<Eigen::Index>(n)) = (f0 - Mat3::Identity()) * fbar.mesh().node(n);
  Eigen::VectorXd f, f_plain;
  op.evaluate(u, f, nullptr);
  op_plain.evaluate(u, f_plain, nullptr);
  MaterialResponse r;
  law->evaluate(f0, {}, {}, r);
  const Mat3 sigma = r.stress * f0.transpose() / f0.determinant();
  Eigen::Matrix<double, 1, 6> expected;
  expected << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2), sigma(0, 2);
  const double scale = expected.cwiseAbs().maxCoeff();
  for (Eigen::Index q = 0; q < op.cauchy_stress().rows(); ++q)
    CHECK((op.cauchy_stress().row(q) - expected).cwiseAbs().maxCoeff() <= 1e-10 * scale);
  CHECK(op.strain_energy() == Approx(r.energy_density * 2.0 * 1.0 * 0.5).epsilon(1e-10));
  INFO("|f_fbar - f_plain| / |f_plain| = " << (f - f_plain).norm() / f_plain.norm());
  CHECK((f - f_plain).norm() <= 1e-10 * f_plain.norm());
}

TEST_CASE("f-bar hex8: the tangent equals finite differences and is symmetric",
          "[fem][nonlinear][fbar]") {
  SECTION("hyperelastic laws: the Hessian of int W(F_bar) dV") {
    for (std::shared_ptr<const MaterialLaw> law :
         {std::shared_ptr<const MaterialLaw>(std::make_shared<NeoHookeLaw>(kE, 0.49, kRho)),
          std::shared_ptr<const MaterialLaw>(
              std::make_shared<DecoupledNeoHookeLaw>(kE, 0.3, kRho))}) {
      Model m = fbar_box(law, 7);
      NonlinearOperator op(m);
      const Eigen::VectorXd u = test::large_deformation(m.mesh(), 3);
      // central differences: error O(h^2) ~ 1e-10, round-off ~ 1e-16 / h ~ 1e-10
      CHECK(test::tangent_fd_error(op, u, 1e-6, 4, 11) < 1e-6);
      Eigen::VectorXd f;
      SparseMatrix k;
      op.evaluate(u, f, &k);
      const SparseMatrix kt = k.transpose();
      INFO("|K - K^T| / |K| = " << (k - kt).norm() / k.norm());
      CHECK((k - kt).norm() <= 1e-12 * k.norm());
    }
  }
  SECTION("small-strain J2 from a plastic history") {
    auto law =
        std::make_shared<J2PlasticityLaw>(200e9, 0.3, 7800.0, HardeningCurve::linear(250e6, 2e9));
    Model m = fbar_box(law, 9);
    NonlinearOperator op(m);
    test::Lcg rng(4);
    Eigen::VectorXd u(3 * static_cast<Eigen::Index>(m.mesh().num_nodes())), f;
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = 0.01 * rng.next();
    op.evaluate(u, f, nullptr);
    op.commit();
    Eigen::VectorXd u2 = u;
    for (Eigen::Index i = 0; i < u.size(); ++i) u2[i] += 0.004 * rng.next();
    CHECK(test::tangent_fd_error(op, u2, 1e-9, 4, 13) < 1e-6);
  }
}

TEST_CASE("f-bar hex8 on the linear path is refused with the reason", "[fem][fbar]") {
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}),
          Material{kE, 0.3, kRho});
  m.set_hex8_formulation(Hex8Formulation::FBar);
  CHECK_THROWS_WITH(StructuralSolver(std::move(m)),
                    Catch::Contains("nonlinear path") && Catch::Contains("incompatible-mode"));
}

#ifdef _OPENMP
TEST_CASE("nonlinear operator: the internal force and tangent do not depend on the thread count",
          "[fem][nonlinear][threads]") {
  // The elements are evaluated in parallel and summed in element order: 1 and 2 threads must
  // give the same bits (restarts and repeated coupling windows rely on it). 12 x 10 x 10 F-bar
  // Hex8 (1200 elements: two chunks of the operator, the second partial) under a large
  // deformation.
  BoxSpec spec{Vec3::Zero(), Vec3(2.0, 1.0, 0.5), {12, 10, 10}, ElementType::Hex8};
  Mesh mesh = make_box_mesh(spec);
  Model m(std::move(mesh));
  m.set_material_law(std::make_shared<NeoHookeLaw>(kE, 0.45, kRho));
  m.set_hex8_formulation(Hex8Formulation::FBar);
  const Eigen::VectorXd u = test::large_deformation(m.mesh(), 3);
  const int before = omp_get_max_threads();
  auto evaluate = [&](int threads, Eigen::VectorXd& f, SparseMatrix& k, double& energy) {
    omp_set_num_threads(threads);
    NonlinearOperator op(m);
    op.evaluate(u, f, &k);
    energy = op.strain_energy();
  };
  Eigen::VectorXd f1, f2;
  SparseMatrix k1, k2;
  double e1 = 0.0, e2 = 0.0;
  evaluate(1, f1, k1, e1);
  evaluate(2, f2, k2, e2);
  omp_set_num_threads(before);
  REQUIRE(f1.norm() > 0.0);
  CHECK(f1 == f2);
  REQUIRE(k1.nonZeros() == k2.nonZeros());
  CHECK(std::equal(k1.valuePtr(), k1.valuePtr() + k1.nonZeros(), k2.valuePtr()));
  CHECK(e1 == e2);
}
#endif
