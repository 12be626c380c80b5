// The BLAS under CHOLMOD's supernodes must run each call on one thread: a threaded BLAS splits a
// product over the cores and sums in an order that depends on them, so a plate factorised in a
// process of its own would give other bits than the same plate in a shared process. The test
// asks the loaded library itself (its own API, looked up here, independently of
// src/blas_runtime.cpp), after a factorisation, how many threads a call may use; and, where the
// build chose a BLAS folder, that the library answering dgemm_ is the one from that folder,
// whatever Debian's libblas.so.3 alternative points at.
#include <dlfcn.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <string>

#include "partita/fem/blas_runtime.hpp"
#include "partita/fem/linear_solver.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace partita::fem;

namespace {

// The 5-point Laplacian on an n x n grid (Dirichlet): symmetric positive definite, and its
// nested-dissection factor has dense supernodes, which CHOLMOD hands to the BLAS.
SparseMatrix laplacian(int n) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      t.emplace_back(id(i, j), id(i, j), 4.0);
      if (i > 0) t.emplace_back(id(i, j), id(i - 1, j), -1.0);
      if (i + 1 < n) t.emplace_back(id(i, j), id(i + 1, j), -1.0);
      if (j > 0) t.emplace_back(id(i, j), id(i, j - 1), -1.0);
      if (j + 1 < n) t.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  SparseMatrix a(n * n, n * n);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

template <class F>
F find(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_DEFAULT, name));
}

}  // namespace

TEST_CASE("blas: a CHOLMOD factorisation calls a BLAS that runs on one thread",
          "[fem][linear-solver][blas]") {
  if (!cholmod_available()) {
    WARN("built without CHOLMOD: the FEM calls no BLAS");
    return;
  }
#ifdef _OPENMP
  const int omp_threads = omp_get_max_threads();
#endif
  const int n = 60;
  const SparseMatrix a = laplacian(n);
  SparseFactorisation f(LinearSolver::Cholmod, FillOrdering::Automatic);
  f.analyze(a);
  REQUIRE(f.factorize(a));
  const Eigen::VectorXd x_exact = Eigen::VectorXd::LinSpaced(n * n, -1.0, 2.0);
  Eigen::VectorXd x;
  f.solve(a * x_exact, x);
  CHECK((x - x_exact).norm() <= 1e-10 * x_exact.norm());
#ifdef _OPENMP
  // pinning the BLAS leaves the caller's OpenMP threads alone (an OpenMP OpenBLAS would set both)
  CHECK(omp_get_max_threads() == omp_threads);
#endif

  void* dgemm = dlsym(RTLD_DEFAULT, "dgemm_");
  REQUIRE(dgemm != nullptr);  // CHOLMOD links the BLAS
  Dl_info where{};
  REQUIRE(dladdr(dgemm, &where) != 0);
  const std::string library = where.dli_fname ? where.dli_fname : "";
  INFO("dgemm_ from " << library);

  // OpenBLAS: 0 = a sequential build; otherwise one thread per call is what it must use now
  if (auto parallel = find<int (*)()>("openblas_get_parallel")) {
    auto threads = find<int (*)()>("openblas_get_num_threads");
    INFO("OpenBLAS, parallel mode " << parallel());
    REQUIRE(threads != nullptr);
    CHECK((parallel() == 0 || threads() == 1));
  }
  if (auto threads = find<std::int64_t (*)()>("bli_thread_get_num_threads")) {
    INFO("BLIS");
    CHECK(threads() <= 1);
  }
  if (auto threads = find<int (*)()>("MKL_Get_Max_Threads")) {
    INFO("MKL");
    CHECK(threads() == 1);
  }

  const BlasInfo info = blas_info();
  CHECK(info.library == library);
  CHECK(info.threads == 1);
  const std::string dir = configured_blas_dir();
  if (!dir.empty()) {
    INFO("the build chose the BLAS in " << dir);
    CHECK(library.rfind(dir + "/", 0) == 0);
    CHECK(info.threading == "serial");
  }
}
