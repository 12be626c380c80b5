// The sparse direct solvers of the implicit paths: CHOLMOD (supernodal L L^T, when built in) and
// Eigen's SimplicialLDLT solve the same symmetric positive definite systems, whose solution is
// unique, so their displacements agree to round-off (the brief's bound: 1e-10 relative, about
// cond(K_eff) eps for these well-conditioned plates); and the factorisation contract
// (symbolic analysis reused, singular and indefinite matrices) against exact linear algebra.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "fem_test_helpers.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/linear_solver.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using partita::fem::test::seed_plate;

namespace {

double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / b.norm();
}

SolverOptions with_solver(LinearSolver solver, SolverOptions o = {}) {
  o.linear_solver = solver;
  return o;
}

}  // namespace

TEST_CASE("linear solver: auto resolves to cholmod exactly when it is built in",
          "[fem][linear-solver]") {
  CHECK(resolve(LinearSolver::Automatic) ==
        (cholmod_available() ? LinearSolver::Cholmod : LinearSolver::EigenLdlt));
  CHECK(resolve(LinearSolver::EigenLdlt) == LinearSolver::EigenLdlt);
  CHECK(to_string(LinearSolver::EigenLdlt) == "eigen-ldlt");
  CHECK(to_string(LinearSolver::Cholmod) == "cholmod");
  if (!cholmod_available()) {
    // asking for it is a clear error, naming what to do instead
    CHECK_THROWS_WITH(StructuralSolver(seed_plate(2, 1), with_solver(LinearSolver::Cholmod)),
                      Catch::Contains("no CHOLMOD") && Catch::Contains("eigen-ldlt"));
  }
}

TEST_CASE("linear solver: CHOLMOD and Eigen's LDLT agree to 1e-10 on the plate, static and Newmark",
          "[fem][linear-solver]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: nothing to compare");
    return;
  }
  const Model model = seed_plate(20, 2);
  for (auto ordering : {FillOrdering::Nesdis, FillOrdering::Metis, FillOrdering::Amd}) {
    INFO("CHOLMOD ordering " << to_string(ordering));
    // static: K u = F; the corner reactions carry the whole load p A = 4 N (equilibrium)
    SolverOptions chol = with_solver(LinearSolver::Cholmod);
    chol.fill_ordering = ordering;
    StructuralSolver a(model, with_solver(LinearSolver::EigenLdlt));
    StructuralSolver b(model, chol);
    a.solve_static();
    b.solve_static();
    CHECK(relative_difference(b.displacement(), a.displacement()) <= 1e-10);
    CHECK(b.reaction("corners")[2] == Approx(10e3 * 0.02 * 0.02).epsilon(1e-9));

    // Newmark, consistent mass, load applied at t = 0: 30 steps of the plate's vibration
    StructuralSolver c(model, with_solver(LinearSolver::EigenLdlt));
    StructuralSolver d(model, chol);
    double worst = 0.0;
    for (int k = 0; k < 30; ++k) {
      c.step(1e-6);
      d.step(1e-6);
      worst = std::max(worst, relative_difference(d.displacement(), c.displacement()));
    }
    CHECK(c.max_displacement() > 0.0);
    CHECK(worst <= 1e-10);
    CHECK(d.timings().factorisations == 1);  // K_eff factorised once for all steps
  }
}

TEST_CASE("linear solver: Newton on CHOLMOD's or the threaded factor agrees with Eigen's LDLT",
          "[fem][linear-solver][nonlinear]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: nothing to compare");
    return;
  }
  // A Neo-Hooke rubber plate (the seed geometry, 8 x 8 x 2 cells) under 200 kPa: large
  // deflection, Newton to |R| <= 1e-12 |F| so that both converge to round-off.
  auto make = [](LinearSolver solver, FactorThreading factor = FactorThreading::Serial) {
    Model m = seed_plate(8, 2);
    Model rubber(m.mesh());
    rubber.set_material_law(std::make_shared<NeoHookeLaw>(5e6, 0.45, 1100.0));
    rubber.fix("lateral", {0, 1, 2});
    rubber.add_pressure("zmax", 200e3);
    SolverOptions o = with_solver(solver);
    o.factor_threading = factor;
    o.newton.force_tolerance = 1e-12;
    o.newton.load_steps = 2;
    return std::make_unique<StructuralSolver>(std::move(rubber), o);
  };
  auto a = make(LinearSolver::EigenLdlt);
  auto b = make(LinearSolver::Cholmod);
  // the tangents through partita's threaded factorisation (asked for: the factor is small)
  auto t = make(LinearSolver::Cholmod, FactorThreading::Threaded);
  a->solve_static();
  b->solve_static();
  t->solve_static();
  REQUIRE(a->max_displacement() > 1e-4);  // large deflection of a 2 mm plate: nonlinear
  for (const auto& r : b->static_reports()) CHECK(r.converged);
  for (const auto& r : t->static_reports()) CHECK(r.converged);
  CHECK(relative_difference(b->displacement(), a->displacement()) <= 1e-10);
  CHECK(relative_difference(t->displacement(), a->displacement()) <= 1e-10);
  // Newmark from rest under the same load (one Newton solve per step, the tangent
  // refactorised per iteration on the analysed pattern)
  auto c = make(LinearSolver::EigenLdlt);
  auto d = make(LinearSolver::Cholmod);
  auto e = make(LinearSolver::Cholmod, FactorThreading::Threaded);
  double worst = 0.0, worst_threaded = 0.0;
  for (int k = 0; k < 5; ++k) {
    c->step(1e-4);
    d->step(1e-4);
    e->step(1e-4);
    CHECK(d->newmark_report().converged);
    CHECK(e->newmark_report().converged);
    worst = std::max(worst, relative_difference(d->displacement(), c->displacement()));
    worst_threaded =
        std::max(worst_threaded, relative_difference(e->displacement(), c->displacement()));
  }
  CHECK(d->max_displacement() > 1e-5);
  CHECK(worst <= 1e-10);
  CHECK(worst_threaded <= 1e-10);
}

TEST_CASE("linear solver: a plate free to move rigidly is a clear error with either solver",
          "[fem][linear-solver]") {
  for (auto solver : {LinearSolver::EigenLdlt, LinearSolver::Cholmod}) {
    if (solver == LinearSolver::Cholmod && !cholmod_available()) continue;
    INFO(to_string(solver));
    // lateral nodes fixed in x and y only: the plate can translate in z (singular K_ff)
    Model m = seed_plate(4, 1);
    Model free_z(m.mesh(), Material{250e9, 0.3, 7850});
    free_z.fix("lateral", {0, 1});
    free_z.add_pressure("zmax", 10e3);
    StructuralSolver s(std::move(free_z), with_solver(solver));
    CHECK_THROWS_WITH(s.solve_static(),
                      Catch::Contains("singular or indefinite") && Catch::Contains("rigid-body"));
  }
}

TEST_CASE("linear solver: analysis reused across values, solutions exact, indefinite matrices",
          "[fem][linear-solver]") {
  // A = the 1D Laplacian tridiag(-1, 2, -1) of size n (SPD), stored with both triangles.
  const int n = 200;
  SparseMatrix a(n, n);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0);
    if (i + 1 < n) {
      t.emplace_back(i, i + 1, -1.0);
      t.emplace_back(i + 1, i, -1.0);
    }
  }
  a.setFromTriplets(t.begin(), t.end());
  // exact solution of A x = e_1 / ... : x_i = (n - i) / (n + 1) for b = e_0 (i = 0 ... n-1)
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  b[0] = 1.0;
  Eigen::VectorXd exact(n);
  for (int i = 0; i < n; ++i) exact[i] = static_cast<double>(n - i) / (n + 1);

  for (auto solver : {LinearSolver::EigenLdlt, LinearSolver::Cholmod}) {
    if (solver == LinearSolver::Cholmod && !cholmod_available()) continue;
    INFO(to_string(solver));
    SparseFactorisation f(solver);
    CHECK(f.solver() == solver);
    f.analyze(a);
    REQUIRE(f.factorize(a));
    Eigen::VectorXd x;
    f.solve(b, x);
    CHECK(relative_difference(x, exact) <= 1e-12);
    // new values, same pattern: no new analysis needed; (3 A) x = b gives x / 3
    const SparseMatrix a3 = 3.0 * a;
    REQUIRE(f.factorize(a3));
    f.solve(b, x);
    CHECK(relative_difference(3.0 * x, exact) <= 1e-12);
    CHECK(f.factor_nonzeros() >= 2 * n - 1);  // L of a tridiagonal matrix: at least its band

    // an indefinite matrix: [[1, 2], [2, 1]] (eigenvalues 3 and -1), x = A^-1 (1, 0) = (-1/3, 2/3)
    SparseMatrix m(2, 2);
    m.insert(0, 0) = 1.0;
    m.insert(0, 1) = 2.0;
    m.insert(1, 0) = 2.0;
    m.insert(1, 1) = 1.0;
    m.makeCompressed();
    SparseFactorisation spd(solver);
    spd.analyze(m);
    CHECK_FALSE(spd.factorize(m));  // not positive definite: refused
    SparseFactorisation indef(solver, FillOrdering::Automatic,
                              SparseFactorisation::Matrix::SymmetricIndefiniteAllowed);
    indef.analyze(m);
    REQUIRE(indef.factorize(m));  // Newton's tangents past a limit point: L D L^T
    Eigen::VectorXd y;
    indef.solve(Eigen::Vector2d(1.0, 0.0), y);
    CHECK(y[0] == Approx(-1.0 / 3.0).epsilon(1e-14));
    CHECK(y[1] == Approx(2.0 / 3.0).epsilon(1e-14));
  }
}
