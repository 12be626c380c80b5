// The threaded supernodal factorisation (FactorThreading::Threaded): partita's left-looking
// numeric factorisation over CHOLMOD's symbolic analysis. What must hold: the factor solves
// A x = b to round-off (against a known solution, CHOLMOD's own factor and Eigen's L D L^T); the
// factor does not depend on the number of threads, bit for bit, in every repeat; a matrix that is
// not positive definite is refused (or, where allowed, handed to the L D L^T fallback); a new
// pattern is analysed again; the automatic choice takes it only for large factors; and the
// plate's static and Newmark results agree with Eigen's solver to 1e-10.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "fem_test_helpers.hpp"
#include "partita/fem/linear_solver.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using namespace partita::fem::test;

namespace {

// Sets the factor threading and CHOLMOD's own solve (so that only the factor differs between
// two factorisations).
void use(SparseFactorisation& f, FactorThreading threading) {
  f.set_factor_threading(threading);
  f.set_solve_threading(SolveThreading::Serial);
}

}  // namespace

TEST_CASE("threaded factorisation: solves grid Laplacians to round-off, as CHOLMOD's factor does",
          "[fem][linear-solver][threaded-factorisation]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded factorisation works on CHOLMOD's analysis");
    return;
  }
  CHECK(to_string(FactorThreading::Threaded) == "threaded");
  CHECK(to_string(FactorThreading::Serial) == "serial");
  // a deep tree with wide top separators (shared rows), and a flat one (many small supernodes)
  for (const auto& dims : {std::vector<int>{22, 22, 22}, std::vector<int>{60, 60, 2}}) {
    const SparseMatrix a = grid_laplacian(dims[0], dims[1], dims[2]);
    const Eigen::VectorXd exact = known_solution(a.rows());
    const Eigen::VectorXd b = a * exact;
    for (auto ordering : {FillOrdering::Nesdis, FillOrdering::Metis, FillOrdering::Amd}) {
      INFO("grid " << dims[0] << "x" << dims[1] << "x" << dims[2] << ", ordering "
                   << to_string(ordering));
      SparseFactorisation threaded(LinearSolver::Cholmod, ordering);
      SparseFactorisation serial(LinearSolver::Cholmod, ordering);
      use(threaded, FactorThreading::Threaded);
      use(serial, FactorThreading::Serial);
      threaded.analyze(a);
      serial.analyze(a);
      REQUIRE(threaded.factorize(a));
      REQUIRE(serial.factorize(a));
      CHECK(threaded.threaded_factorisation());
      CHECK_FALSE(serial.threaded_factorisation());
      CHECK(threaded.factor_nonzeros() == serial.factor_nonzeros());
      Eigen::VectorXd x, y;
      threaded.solve(b, x);
      serial.solve(b, y);
      // cond(A) <= 12.01 / 0.01: round-off of order 1e-13
      CHECK(relative_difference(x, exact) <= 1e-12);
      CHECK(relative_difference(x, y) <= 1e-12);
      // new values, same pattern: 2 A x = b gives x / 2 (the schedule is kept)
      const SparseMatrix a2 = 2.0 * a;
      REQUIRE(threaded.factorize(a2));
      threaded.solve(b, x);
      CHECK(relative_difference(2.0 * x, exact) <= 1e-12);
      // the threaded solve on the threaded factor
      threaded.set_solve_threading(SolveThreading::Threaded);
      REQUIRE(threaded.factorize(a));
      CHECK(threaded.threaded_solve());
      threaded.solve(b, x);
      CHECK(relative_difference(x, exact) <= 1e-12);
    }
  }
}

TEST_CASE("threaded factorisation: the same bits on 1, 2, 3 and 4 threads and on every repeat",
          "[fem][linear-solver][threaded-factorisation]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded factorisation works on CHOLMOD's analysis");
    return;
  }
  const int before = threads_available();
  const SparseMatrix a = grid_laplacian(24, 24, 20);
  const Eigen::VectorXd b = a * known_solution(a.rows());
  SparseFactorisation f(LinearSolver::Cholmod);
  use(f, FactorThreading::Threaded);
  f.analyze(a);
  use_threads(1);
  REQUIRE(f.factorize(a));
  REQUIRE(f.threaded_factorisation());
  Eigen::VectorXd reference;
  f.solve(b, reference);
  check_same_bits_on_threads(reference, [&] {
    REQUIRE(f.factorize(a));
    Eigen::VectorXd x;
    f.solve(b, x);
    return x;
  });
  use_threads(before);
}

TEST_CASE("threaded factorisation: a matrix that is not positive definite is refused",
          "[fem][linear-solver][threaded-factorisation]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded factorisation works on CHOLMOD's analysis");
    return;
  }
  // shift -1: the Laplacian's smallest eigenvalues (about 0.3 here) go below zero, the largest
  // stay positive: indefinite, and not by a single bad diagonal entry
  const SparseMatrix a = grid_laplacian(16, 16, 16, -1.0);
  SparseFactorisation spd(LinearSolver::Cholmod);
  use(spd, FactorThreading::Threaded);
  spd.analyze(a);
  CHECK_FALSE(spd.factorize(a));
  CHECK_FALSE(spd.threaded_factorisation());
  // after the failure the same object factorises an SPD matrix of the same pattern
  const SparseMatrix good = grid_laplacian(16, 16, 16);
  REQUIRE(spd.factorize(good));
  CHECK(spd.threaded_factorisation());
  // where indefinite matrices are allowed (Newton's tangents), the L D L^T fallback solves it
  SparseFactorisation indefinite(LinearSolver::Cholmod, FillOrdering::Nesdis,
                                 SparseFactorisation::Matrix::SymmetricIndefiniteAllowed);
  use(indefinite, FactorThreading::Threaded);
  indefinite.analyze(a);
  REQUIRE(indefinite.factorize(a));
  CHECK_FALSE(indefinite.threaded_factorisation());
  const Eigen::VectorXd exact = known_solution(a.rows());
  Eigen::VectorXd x;
  indefinite.solve(a * exact, x);
  CHECK(relative_difference(x, exact) <= 1e-9);
}

TEST_CASE("threaded factorisation: a new pattern of the same size is analysed again",
          "[fem][linear-solver][threaded-factorisation]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded factorisation works on CHOLMOD's analysis");
    return;
  }
  // two patterns of 4,000 unknowns: a 20x20x10 grid, and a 40x10x10 grid
  const SparseMatrix a = grid_laplacian(20, 20, 10), c = grid_laplacian(40, 10, 10);
  SparseFactorisation f(LinearSolver::Cholmod);
  use(f, FactorThreading::Threaded);
  f.analyze(a);
  REQUIRE(f.factorize(a));
  REQUIRE(f.factorize(c));  // without analyze(): the old schedule would not fit
  CHECK(f.threaded_factorisation());
  const Eigen::VectorXd exact = known_solution(c.rows());
  Eigen::VectorXd x;
  f.solve(c * exact, x);
  CHECK(relative_difference(x, exact) <= 1e-12);
}

TEST_CASE("threaded factorisation: automatic only for large factors, and the plate agrees with Eigen",
          "[fem][linear-solver][threaded-factorisation][slow]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded factorisation works on CHOLMOD's analysis");
    return;
  }
  const SparseMatrix small = grid_laplacian(10, 10, 10);
  SparseFactorisation automatic(LinearSolver::Cholmod);
  automatic.analyze(small);
  REQUIRE(automatic.factorize(small));
  CHECK(automatic.factor_nonzeros() < 2e6);
  CHECK_FALSE(automatic.threaded_factorisation());
  const SparseMatrix large = grid_laplacian(32, 32, 32);
  automatic.analyze(large);
  REQUIRE(automatic.factorize(large));
  CHECK(automatic.factor_nonzeros() >= 2e6);
  CHECK(automatic.threaded_factorisation());

  // the seed plate, 40 x 40 x 4 Hex8 (25k dofs, a factor of ~7e6 entries: the threaded
  // factorisation by default): static (corner reaction p A = 4 N) and 10 Newmark steps against
  // Eigen's L D L^T, within 1e-10
  const double l = 0.02;
  const Model model = seed_plate(40, 4);
  SolverOptions threaded, eigen;
  threaded.linear_solver = LinearSolver::Cholmod;
  threaded.factor_threading = FactorThreading::Threaded;
  eigen.linear_solver = LinearSolver::EigenLdlt;
  StructuralSolver st(model, threaded), se(model, eigen);
  st.solve_static();
  se.solve_static();
  CHECK(relative_difference(st.displacement(), se.displacement()) <= 1e-10);
  CHECK(st.reaction("corners")[2] == Approx(10e3 * l * l).epsilon(1e-9));
  StructuralSolver dt(model, threaded), de(model, eigen);
  double worst = 0.0;
  for (int k = 0; k < 10; ++k) {
    dt.step(1e-6);
    de.step(1e-6);
    worst = std::max(worst, relative_difference(dt.displacement(), de.displacement()));
  }
  CHECK(dt.max_displacement() > 0.0);
  CHECK(worst <= 1e-10);
}
