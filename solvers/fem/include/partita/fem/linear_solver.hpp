#pragma once
#include <Eigen/Core>
#include <memory>
#include <string>

#include "partita/fem/types.hpp"

namespace partita::fem {

// The sparse direct solver of the implicit paths (static, Newmark, Newton):
//   Cholmod    SuiteSparse's CHOLMOD, supernodal LL^T (dense BLAS kernels on supernodes) with a
//              fill-reducing ordering (FillOrdering); only when partita was built with it
//              (CMake option PARTITA_CHOLMOD, on when CHOLMOD is found);
//   EigenLdlt  Eigen's SimplicialLDLT with AMD: always there, one column at a time;
//   Automatic  Cholmod when built in, else EigenLdlt.
// Both factorise the symmetric matrix's lower triangle and agree to round-off.
enum class LinearSolver { Automatic, Cholmod, EigenLdlt };
// CHOLMOD's fill-reducing ordering: Metis (METIS_NodeND nested dissection), Nesdis (CHOLMOD's
// own nested dissection: METIS edge separators, then constrained minimum degree on the parts),
// or Amd (approximate minimum degree). Automatic = Nesdis, the smallest factor and the fastest
// factorisation and solve on the plates of bench_fem_plate (figures in bench/README.md).
enum class FillOrdering { Automatic, Metis, Nesdis, Amd };
// The two triangular solves with a CHOLMOD factor (each solve() reads the whole factor twice,
// which is memory-bound): Threaded splits the factor's elimination tree over the OpenMP threads
// (independent subtrees as tasks, the top separators shared row- or columnwise), Serial is
// CHOLMOD's own solve on one thread; Automatic = Threaded for factors of at least 2e6 entries,
// Serial below. Either way the solution does not depend on the number of threads (the order of
// every sum is fixed by the factor's structure); Threaded and Serial differ by round-off.
enum class SolveThreading { Automatic, Threaded, Serial };
// The numeric factorisation with CHOLMOD's symbolic analysis: Threaded is partita's supernodal
// factorisation (the same left-looking method and BLAS kernels as CHOLMOD's, disjoint subtrees of
// the elimination tree as OpenMP tasks, the rows of the large supernodes near the root shared),
// Serial is CHOLMOD's own on one thread; Automatic = Threaded for factors of at least 2e6 entries,
// Serial below. Either way the factor does not depend on the number of threads (every sum's
// order is fixed by the factor's structure); Threaded and Serial differ by round-off.
enum class FactorThreading { Automatic, Threaded, Serial };

// Whether this build has CHOLMOD (PARTITA_CHOLMOD).
bool cholmod_available();
// Automatic resolved for this build.
LinearSolver resolve(LinearSolver solver);
// "auto", "cholmod", "eigen-ldlt" (the names the FEM adapter accepts).
std::string to_string(LinearSolver solver);
std::string to_string(FillOrdering ordering);
std::string to_string(SolveThreading threading);
std::string to_string(FactorThreading threading);
// The instruction set of the threaded solve's kernels on this processor: "avx2-fma" or "sse2"
// (environment PARTITA_FEM_SOLVE_KERNELS=sse2 forces the portable set). The two differ by
// round-off (a fused multiply-add rounds once), each gives the same bits on any thread count.
std::string threaded_solve_kernels();

// A symmetric positive definite sparse factorisation A = L D L^T (or L L^T) with its symbolic
// analysis kept: analyze() once per sparsity pattern, factorize() whenever the values change,
// solve() as often as needed. Only the lower triangle of A is read (the upper may be stored).
// Throws Error for a backend that is not built in. Deterministic: the same matrix gives the
// same factor and the same solutions, bit for bit (restart files rely on it).
class SparseFactorisation {
 public:
  // SymmetricPositiveDefinite: factorize() fails unless A is numerically positive definite.
  // SymmetricIndefiniteAllowed (Newton's tangents, which may lose definiteness): an L D L^T
  // without pivoting that fails only on a zero pivot; CHOLMOD's L L^T then falls back to
  // Eigen's L D L^T for a matrix that is not positive definite.
  enum class Matrix { SymmetricPositiveDefinite, SymmetricIndefiniteAllowed };
  explicit SparseFactorisation(LinearSolver solver = LinearSolver::Automatic,
                               FillOrdering ordering = FillOrdering::Automatic,
                               Matrix kind = Matrix::SymmetricPositiveDefinite);
  ~SparseFactorisation();
  SparseFactorisation(const SparseFactorisation&) = delete;
  SparseFactorisation& operator=(const SparseFactorisation&) = delete;

  LinearSolver solver() const { return solver_; }  // resolved: never Automatic
  // Symbolic analysis (ordering, elimination tree, supernodes) of A's pattern.
  void analyze(const SparseMatrix& a);
  // Numeric factorisation of A with the analysed pattern (analyze() first, or again when the
  // pattern changed). Returns false when A is not numerically positive definite: a pivot <= 0
  // or min pivot <= 1e-14 max pivot (rigid-body motion not prevented, an inverted element);
  // with SymmetricIndefiniteAllowed only for a zero pivot.
  bool factorize(const SparseMatrix& a);
  // x = A^-1 b with the last successful factorisation. No allocation once x and the
  // backend's work space are sized (the first call of a given size sizes them).
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  // Nonzeros of the factor L, its diagonal included (0 before the first factorize()).
  double factor_nonzeros() const;
  // How solve() runs with a CHOLMOD factor (no effect with Eigen's); takes effect at the next
  // factorize().
  void set_solve_threading(SolveThreading threading);
  // Whether the last factorisation is solved by the threaded solve.
  bool threaded_solve() const;
  // How factorize() runs with CHOLMOD (no effect with Eigen's); takes effect at the next
  // factorize().
  void set_factor_threading(FactorThreading threading);
  // Whether the last factorisation was partita's threaded one.
  bool threaded_factorisation() const;

  struct Impl;  // the backend (defined in linear_solver.cpp)

 private:
  LinearSolver solver_;
  std::unique_ptr<Impl> impl_;
  bool empty_ = false;  // a 0 x 0 matrix
};

// f.factorize(a), or Error "<what> is singular or indefinite: ..." with what to fix (the
// Dirichlet conditions leave a rigid-body motion free, or an element is inverted).
void factorize_or_throw(SparseFactorisation& f, const SparseMatrix& a, const char* what);

}  // namespace partita::fem
