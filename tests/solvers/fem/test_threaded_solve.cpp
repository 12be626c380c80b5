// The threaded supernodal solve (SolveThreading::Threaded): the two triangular solves with
// CHOLMOD's factor, the elimination tree split into independent subtrees and shared top
// separators. What must hold: it solves A x = b (to round-off, against a known solution and
// against CHOLMOD's own solve and Eigen's L D L^T); its result does not depend on the number of
// threads, bit for bit (restarts and thread counts must not change a run); and the automatic
// choice takes it only for large factors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "fem_test_helpers.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/linear_solver.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using namespace partita::fem::test;

TEST_CASE("threaded solve: solves a grid Laplacian to round-off and agrees with CHOLMOD's solve",
          "[fem][linear-solver][threaded-solve]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded solve works on CHOLMOD's factor");
    return;
  }
  CHECK(to_string(SolveThreading::Threaded) == "threaded");
  const char* forced = std::getenv("PARTITA_FEM_SOLVE_KERNELS");
  if (forced != nullptr && std::string(forced) == "sse2") CHECK(threaded_solve_kernels() == "sse2");
  INFO("kernels " << threaded_solve_kernels());
  const SparseMatrix a = grid_laplacian(24, 24, 12);  // 6,912 unknowns
  const Eigen::VectorXd exact = known_solution(a.rows());
  const Eigen::VectorXd b = a * exact;
  for (auto ordering : {FillOrdering::Nesdis, FillOrdering::Metis, FillOrdering::Amd}) {
    INFO("ordering " << to_string(ordering));
    SparseFactorisation threaded(LinearSolver::Cholmod, ordering);
    threaded.set_solve_threading(SolveThreading::Threaded);
    SparseFactorisation serial(LinearSolver::Cholmod, ordering);
    serial.set_solve_threading(SolveThreading::Serial);
    threaded.analyze(a);
    serial.analyze(a);
    REQUIRE(threaded.factorize(a));
    REQUIRE(serial.factorize(a));
    CHECK(threaded.threaded_solve());
    CHECK_FALSE(serial.threaded_solve());
    Eigen::VectorXd x, y;
    threaded.solve(b, x);
    serial.solve(b, y);
    // cond(A) < 12.01 / 0.01 ~ 1.2e3: round-off of the order 1e-13 at most
    CHECK(relative_difference(x, exact) <= 1e-12);
    CHECK(relative_difference(x, y) <= 1e-12);
    // new values with the same pattern (the schedule is the structure's): 2 A x = b gives x / 2
    const SparseMatrix a2 = 2.0 * a;
    REQUIRE(threaded.factorize(a2));
    threaded.solve(b, x);
    CHECK(relative_difference(2.0 * x, exact) <= 1e-12);
  }
}

TEST_CASE("threaded solve: the same bits on 1, 2, 3 and 4 threads and on every repeat",
          "[fem][linear-solver][threaded-solve]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded solve works on CHOLMOD's factor");
    return;
  }
  const int before = threads_available();
  const SparseMatrix a = grid_laplacian(20, 20, 16);
  const Eigen::VectorXd b = a * known_solution(a.rows());
  SparseFactorisation f(LinearSolver::Cholmod);
  f.set_solve_threading(SolveThreading::Threaded);
  f.analyze(a);
  REQUIRE(f.factorize(a));
  REQUIRE(f.threaded_solve());
  use_threads(1);
  Eigen::VectorXd reference;
  f.solve(b, reference);
  check_same_bits_on_threads(reference, [&] {
    Eigen::VectorXd x;
    f.solve(b, x);
    return x;
  });
  use_threads(before);
}

TEST_CASE("threaded solve: automatic only for large factors, same plate results either way",
          "[fem][linear-solver][threaded-solve][slow]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the threaded solve works on CHOLMOD's factor");
    return;
  }
  // a small factor: CHOLMOD's own solve; asked for, the threaded one
  const SparseMatrix small = grid_laplacian(10, 10, 10);
  SparseFactorisation automatic(LinearSolver::Cholmod);
  automatic.analyze(small);
  REQUIRE(automatic.factorize(small));
  CHECK(automatic.factor_nonzeros() < 2e6);
  CHECK_FALSE(automatic.threaded_solve());
  automatic.set_solve_threading(SolveThreading::Threaded);
  REQUIRE(automatic.factorize(small));
  CHECK(automatic.threaded_solve());

  // the seed plate (20 x 20 x 2 Hex8, 10 kPa on top): static and 30 Newmark steps with the
  // threaded solve against Eigen's L D L^T (the brief's 1e-10) and against CHOLMOD's own solve
  const double l = 0.02;
  const Model model = seed_plate(20, 2);
  SolverOptions threaded, serial, eigen;
  threaded.linear_solver = serial.linear_solver = LinearSolver::Cholmod;
  threaded.solve_threading = SolveThreading::Threaded;
  serial.solve_threading = SolveThreading::Serial;
  eigen.linear_solver = LinearSolver::EigenLdlt;
  StructuralSolver st(model, threaded), ss(model, serial), se(model, eigen);
  st.solve_static();
  ss.solve_static();
  se.solve_static();
  CHECK(relative_difference(st.displacement(), se.displacement()) <= 1e-10);
  CHECK(relative_difference(st.displacement(), ss.displacement()) <= 1e-12);
  CHECK(st.reaction("corners")[2] == Approx(10e3 * l * l).epsilon(1e-9));  // p A = 4 N
  StructuralSolver dt(model, threaded), ds(model, serial), de(model, eigen);
  double worst_eigen = 0.0, worst_serial = 0.0;
  for (int k = 0; k < 30; ++k) {
    dt.step(1e-6);
    ds.step(1e-6);
    de.step(1e-6);
    worst_eigen = std::max(worst_eigen, relative_difference(dt.displacement(), de.displacement()));
    worst_serial =
        std::max(worst_serial, relative_difference(dt.displacement(), ds.displacement()));
  }
  CHECK(dt.max_displacement() > 0.0);
  CHECK(worst_eigen <= 1e-10);
  CHECK(worst_serial <= 1e-10);
}

TEST_CASE("threaded solve: a Newmark run of the plate gives the same bits on 1 and 2 threads",
          "[fem][linear-solver][threaded-solve][slow]") {
  // 40 x 40 x 2 cells: the assembly of K and M is shared among the threads too (element
  // matrices in parallel, added by column ranges in element order); Rayleigh damping brings in
  // K v.
  const Model model = seed_plate(40, 2);
  const int before = threads_available();
  for (auto threading : {SolveThreading::Serial, SolveThreading::Threaded}) {
    if (!cholmod_available() && threading == SolveThreading::Threaded) continue;
    INFO("solve " << to_string(threading));
    SolverOptions o;
    o.solve_threading = threading;
    o.rayleigh_alpha = 50.0;
    o.rayleigh_beta = 1e-8;
    std::vector<Eigen::VectorXd> runs;
    for (int threads : {1, 2}) {
      use_threads(threads);
      StructuralSolver s(model, o);
      for (int k = 0; k < 5; ++k) s.step(1e-6);
      runs.push_back(s.displacement());
    }
    CHECK(runs[0].norm() > 0.0);
    CHECK((runs[0].array() == runs[1].array()).all());
  }
  use_threads(before);
}
