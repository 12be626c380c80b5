#include "partita/fem/linear_solver.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cstring>
#include <mutex>

#include "partita/fem/blas_runtime.hpp"
#include "partita/fem/error.hpp"
#include "supernodal_factorize.hpp"
#include "supernodal_kernels.hpp"
#include "supernodal_solve.hpp"

#ifdef PARTITA_HAS_CHOLMOD
#include <cholmod.h>
#endif

namespace partita::fem {

// Below this ratio of the smallest to the largest pivot d_i of A = L D L^T (for L L^T: the
// squared diagonal of L) the matrix counts as singular: rigid-body motion left free gives
// pivots at round-off level, ~1e-16 of the largest.
namespace {
constexpr double kMinPivotRatio = 1e-14;
}

bool cholmod_available() {
#ifdef PARTITA_HAS_CHOLMOD
  return true;
#else
  return false;
#endif
}

LinearSolver resolve(LinearSolver solver) {
  if (solver != LinearSolver::Automatic) return solver;
  return cholmod_available() ? LinearSolver::Cholmod : LinearSolver::EigenLdlt;
}

std::string to_string(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::Automatic:
      return "auto";
    case LinearSolver::Cholmod:
      return "cholmod";
    case LinearSolver::EigenLdlt:
      return "eigen-ldlt";
  }
  return "?";
}

std::string to_string(FillOrdering ordering) {
  switch (ordering) {
    case FillOrdering::Automatic:
      return "auto";
    case FillOrdering::Metis:
      return "metis";
    case FillOrdering::Nesdis:
      return "nesdis";
    case FillOrdering::Amd:
      return "amd";
  }
  return "?";
}

std::string to_string(SolveThreading threading) {
  switch (threading) {
    case SolveThreading::Automatic:
      return "auto";
    case SolveThreading::Threaded:
      return "threaded";
    case SolveThreading::Serial:
      return "serial";
  }
  return "?";
}

std::string to_string(FactorThreading threading) {
  switch (threading) {
    case FactorThreading::Automatic:
      return "auto";
    case FactorThreading::Threaded:
      return "threaded";
    case FactorThreading::Serial:
      return "serial";
  }
  return "?";
}

std::string threaded_solve_kernels() {
  return detail::supernodal_kernels().name;
}

struct SparseFactorisation::Impl {
  virtual ~Impl() = default;
  virtual void set_solve_threading(SolveThreading) {}
  virtual bool threaded_solve() const { return false; }
  virtual void set_factor_threading(FactorThreading) {}
  virtual bool threaded_factorisation() const { return false; }
  virtual void analyze(const SparseMatrix& a) = 0;
  virtual bool factorize(const SparseMatrix& a) = 0;
  virtual void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  virtual double factor_nonzeros() const = 0;
};

namespace {

// ---------------------------------------------------------------- Eigen's SimplicialLDLT

class EigenLdlt final : public SparseFactorisation::Impl {
 public:
  explicit EigenLdlt(bool indefinite_ok) : indefinite_ok_(indefinite_ok) {}
  void analyze(const SparseMatrix& a) override {
    ldlt_.analyzePattern(a);
    analysed_ = true;
  }
  bool factorize(const SparseMatrix& a) override {
    if (!analysed_) analyze(a);
    ldlt_.factorize(a);
    factorised_ = false;
    if (ldlt_.info() != Eigen::Success) return false;
    const auto d = ldlt_.vectorD();
    if (!indefinite_ok_ && d.size() > 0 &&
        !(d.minCoeff() > kMinPivotRatio * d.cwiseAbs().maxCoeff()))
      return false;
    factorised_ = true;
    return true;
  }
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override {
    if (!factorised_) throw Error("SparseFactorisation::solve: no successful factorisation");
    x = ldlt_.solve(b);
  }
  double factor_nonzeros() const override {
    // L is stored without its unit diagonal
    return factorised_
               ? static_cast<double>(ldlt_.matrixL().nestedExpression().nonZeros() + ldlt_.rows())
               : 0.0;
  }

 private:
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
  bool indefinite_ok_;
  bool analysed_ = false, factorised_ = false;
};

#ifdef PARTITA_HAS_CHOLMOD
// ---------------------------------------------------------------- CHOLMOD, supernodal L L^T

// One CHOLMOD call at a time in the process: its supernodal factorisation and solve call the
// system BLAS, and Debian's serial OpenBLAS gives wrong results now and then when two threads
// call it at once (bench_blas_threads, bench/README.md); its analysis calls METIS, whose random
// generator is one static state. Two solvers in one process may run at the same time (the
// participants of a parallel coupling scheme, each on a thread of its own). Uncontended, the lock
// costs nanoseconds against the call's microseconds; contended, the calls wait for each other.
namespace {
std::mutex& cholmod_mutex() {
  static std::mutex m;
  return m;
}
}  // namespace

class Cholmod final : public SparseFactorisation::Impl {
 public:
  Cholmod(FillOrdering ordering, bool indefinite_ok) : indefinite_ok_(indefinite_ok) {
    // one thread per BLAS call whatever BLAS is loaded: the factor must not depend on the cores
    use_serial_blas();
    cholmod_start(&c_);
    c_.print = 0;  // no output: failures are reported through factorize()'s result
    c_.supernodal = CHOLMOD_SUPERNODAL;
    // One ordering, no trial of others (CHOLMOD's default tries AMD, then METIS when AMD's
    // fill is high): NESDIS measured best on the plates (bench/README.md, FEM). METIS runs
    // with a fixed seed, so the ordering and the factor are the same in every run.
    c_.nmethods = 1;
    switch (ordering) {
      case FillOrdering::Amd:
        c_.method[0].ordering = CHOLMOD_AMD;
        break;
      case FillOrdering::Metis:
        c_.method[0].ordering = CHOLMOD_METIS;
        break;
      case FillOrdering::Automatic:
      case FillOrdering::Nesdis:
        c_.method[0].ordering = CHOLMOD_NESDIS;
        break;
    }
    c_.postorder = 1;
    c_.quick_return_if_not_posdef = 1;
  }
  ~Cholmod() override {
    cholmod_free_factor(&l_, &c_);
    cholmod_free_dense(&x_, &c_);
    cholmod_free_dense(&y_, &c_);
    cholmod_free_dense(&e_, &c_);
    cholmod_finish(&c_);
  }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;

  void analyze(const SparseMatrix& a) override {
    cholmod_free_factor(&l_, &c_);
    cholmod_sparse view = lower_view(a);
    {
      const std::lock_guard<std::mutex> lock(cholmod_mutex());
      l_ = cholmod_analyze(&view, &c_);
    }
    if (l_ == nullptr || c_.status < CHOLMOD_OK) {
      throw Error("CHOLMOD: the symbolic analysis failed (status " + std::to_string(c_.status) +
                  (c_.status == CHOLMOD_OUT_OF_MEMORY ? ", out of memory" : "") + ")");
    }
    factorised_ = false;
    fallback_.reset();
    tree_state_ = TreeState::Unprepared;
    factor_state_ = TreeState::Unprepared;
  }
  bool factorize(const SparseMatrix& a) override {
    if (l_ == nullptr || static_cast<Eigen::Index>(l_->n) != a.rows()) analyze(a);
    factorised_ = false;
    const detail::SparsePattern pattern{static_cast<int>(a.cols()), a.outerIndexPtr(),
                                        a.innerIndexPtr()};
    if (factor_state_ == TreeState::Ready && !(a.isCompressed() && threaded_.same_pattern(pattern)))
      analyze(a);  // another pattern: the analysis and the schedule are the old pattern's
    if (factor_state_ == TreeState::Unprepared) {
      // the schedule depends on the structure alone: built once per analysis
      const bool wanted =
          factor_threading_ == FactorThreading::Threaded ||
          (factor_threading_ == FactorThreading::Automatic && c_.lnz >= kThreadedMinEntries);
      factor_state_ = wanted && a.isCompressed() && l_->is_super && l_->itype == CHOLMOD_INT &&
                              threaded_.prepare(factor_view(), pattern)
                          ? TreeState::Ready
                          : TreeState::Unusable;
    }
    bool positive_definite = false;
    if (factor_state_ == TreeState::Ready) {
      if (l_->xtype == CHOLMOD_PATTERN &&
          !cholmod_change_factor(CHOLMOD_REAL, 1, 1, 1, 1, l_, &c_)) {
        throw Error("CHOLMOD: out of memory for the factor's values (status " +
                    std::to_string(c_.status) + ")");
      }
      const int failed =
          threaded_.factorize(factor_view(), a.valuePtr(), static_cast<double*>(l_->x));
      l_->minor = failed < 0 ? l_->n : static_cast<std::size_t>(failed);
      positive_definite = failed < 0;
    } else {
      cholmod_sparse view = lower_view(a);
      int ok = 0;
      {
        const std::lock_guard<std::mutex> lock(cholmod_mutex());
        ok = cholmod_factorize(&view, l_, &c_);
      }
      if (c_.status == CHOLMOD_OUT_OF_MEMORY)
        throw Error("CHOLMOD: out of memory in the factorisation");
      positive_definite = ok && c_.status != CHOLMOD_NOT_POSDEF && l_->minor >= l_->n;
    }
    // (min_i L_ii / max_i L_ii)^2 = min d / max d of the equivalent L D L^T
    if (positive_definite && !indefinite_ok_)
      positive_definite = cholmod_rcond(l_, &c_) > kMinPivotRatio;
    use_fallback_ = !positive_definite && indefinite_ok_;
    if (use_fallback_) {
      // not positive definite (a Newton tangent past a limit point): L D L^T without pivoting
      if (!fallback_) fallback_ = std::make_unique<EigenLdlt>(true);
      return fallback_->factorize(a);
    }
    factorised_ = positive_definite;
    if (factorised_ && tree_state_ == TreeState::Unprepared) {
      // the schedule depends on the structure alone: built once per analysis
      const bool wanted =
          threading_ == SolveThreading::Threaded ||
          (threading_ == SolveThreading::Automatic && c_.lnz >= kThreadedMinEntries);
      tree_state_ = wanted && l_->is_super && l_->is_ll && l_->itype == CHOLMOD_INT &&
                            l_->xtype == CHOLMOD_REAL && tree_.prepare(factor_view())
                        ? TreeState::Ready
                        : TreeState::Unusable;
    }
    return factorised_;
  }
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override {
    if (use_fallback_) {
      fallback_->solve(b, x);
      return;
    }
    if (!factorised_) throw Error("SparseFactorisation::solve: no successful factorisation");
    if (tree_state_ == TreeState::Ready) {
      x.resize(b.size());
      tree_.solve(factor_view(), b.data(), x.data());
      return;
    }
    cholmod_dense rhs{};
    rhs.nrow = rhs.d = rhs.nzmax = static_cast<std::size_t>(b.size());
    rhs.ncol = 1;
    rhs.x = const_cast<double*>(b.data());
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    // x_, y_, e_ are allocated on the first call and reused while the size is the same
    bool solved = false;
    {
      const std::lock_guard<std::mutex> lock(cholmod_mutex());
      solved = cholmod_solve2(CHOLMOD_A, l_, &rhs, nullptr, &x_, nullptr, &y_, &e_, &c_);
    }
    if (!solved) {
      throw Error("CHOLMOD: the solve failed (status " + std::to_string(c_.status) + ")");
    }
    x.resize(b.size());
    std::memcpy(x.data(), x_->x, sizeof(double) * static_cast<std::size_t>(b.size()));
  }
  void set_solve_threading(SolveThreading threading) override {
    if (threading != threading_) tree_state_ = TreeState::Unprepared;
    threading_ = threading;
  }
  bool threaded_solve() const override {
    return factorised_ && !use_fallback_ && tree_state_ == TreeState::Ready;
  }
  void set_factor_threading(FactorThreading threading) override {
    if (threading != factor_threading_) factor_state_ = TreeState::Unprepared;
    factor_threading_ = threading;
  }
  bool threaded_factorisation() const override {
    return factorised_ && !use_fallback_ && factor_state_ == TreeState::Ready;
  }
  double factor_nonzeros() const override {
    if (use_fallback_) return fallback_->factor_nonzeros();
    return factorised_ ? c_.lnz : 0.0;
  }

 private:
  // A view of A for CHOLMOD (no copy): symmetric, lower triangle used (stype -1: the upper
  // triangle, when stored, is ignored).
  static cholmod_sparse lower_view(const SparseMatrix& a) {
    cholmod_sparse s{};
    s.nrow = static_cast<std::size_t>(a.rows());
    s.ncol = static_cast<std::size_t>(a.cols());
    s.nzmax = static_cast<std::size_t>(a.nonZeros());
    s.p = const_cast<int*>(a.outerIndexPtr());
    s.i = const_cast<int*>(a.innerIndexPtr());
    s.x = const_cast<double*>(a.valuePtr());
    s.nz = a.isCompressed() ? nullptr : const_cast<int*>(a.innerNonZeroPtr());
    s.packed = a.isCompressed() ? 1 : 0;
    s.sorted = 1;  // Eigen keeps the inner indices of a column sorted
    s.stype = -1;
    s.itype = CHOLMOD_INT;
    s.xtype = CHOLMOD_REAL;
    s.dtype = CHOLMOD_DOUBLE;
    return s;
  }

  detail::SupernodalFactor factor_view() const {
    detail::SupernodalFactor f;
    f.n = static_cast<int>(l_->n);
    f.nsuper = static_cast<int>(l_->nsuper);
    f.super = static_cast<const int*>(l_->super);
    f.pi = static_cast<const int*>(l_->pi);
    f.px = static_cast<const int*>(l_->px);
    f.rows = static_cast<const int*>(l_->s);
    f.perm = static_cast<const int*>(l_->Perm);
    f.values = static_cast<const double*>(l_->x);
    return f;
  }

  // The threaded solve (supernodal_solve.hpp) and factorisation (supernodal_factorize.hpp) for
  // factors of at least this many entries (16 MB): below, CHOLMOD's own are as fast (a parallel
  // region costs as much as it saves). Decided by the structure alone, so the results never
  // depend on the number of threads.
  static constexpr double kThreadedMinEntries = 2e6;
  enum class TreeState { Unprepared, Ready, Unusable };

  cholmod_common c_{};
  cholmod_factor* l_ = nullptr;
  detail::SupernodalSolve tree_;
  TreeState tree_state_ = TreeState::Unprepared;
  SolveThreading threading_ = SolveThreading::Automatic;
  detail::SupernodalFactorize threaded_;
  TreeState factor_state_ = TreeState::Unprepared;
  FactorThreading factor_threading_ = FactorThreading::Automatic;
  cholmod_dense *x_ = nullptr, *y_ = nullptr, *e_ = nullptr;
  bool indefinite_ok_;
  bool factorised_ = false;
  bool use_fallback_ = false;
  std::unique_ptr<EigenLdlt> fallback_;  // Eigen's L D L^T of an indefinite matrix
};
#endif

}  // namespace

SparseFactorisation::SparseFactorisation(LinearSolver solver, FillOrdering ordering, Matrix kind)
    : solver_(resolve(solver)) {
  const bool indefinite_ok = kind == Matrix::SymmetricIndefiniteAllowed;
  if (solver_ == LinearSolver::Cholmod) {
#ifdef PARTITA_HAS_CHOLMOD
    impl_ = std::make_unique<Cholmod>(ordering, indefinite_ok);
#else
    (void)ordering;
    throw Error(
        "linear solver 'cholmod': this build of partita has no CHOLMOD (configure with "
        "libsuitesparse-dev installed and -DPARTITA_CHOLMOD=ON); use 'eigen-ldlt' or 'auto'");
#endif
  } else {
    impl_ = std::make_unique<EigenLdlt>(indefinite_ok);
  }
}

SparseFactorisation::~SparseFactorisation() = default;

void SparseFactorisation::analyze(const SparseMatrix& a) {
  if (a.rows() != a.cols()) throw Error("SparseFactorisation: the matrix is not square");
  if (a.rows() > 0) impl_->analyze(a);
}

bool SparseFactorisation::factorize(const SparseMatrix& a) {
  if (a.rows() != a.cols()) throw Error("SparseFactorisation: the matrix is not square");
  empty_ = a.rows() == 0;  // every dof constrained: nothing to factorise
  return empty_ || impl_->factorize(a);
}

void SparseFactorisation::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (empty_) {
    x.resize(0);
    return;
  }
  impl_->solve(b, x);
}

double SparseFactorisation::factor_nonzeros() const {
  return impl_->factor_nonzeros();
}

void SparseFactorisation::set_solve_threading(SolveThreading threading) {
  impl_->set_solve_threading(threading);
}

bool SparseFactorisation::threaded_solve() const {
  return !empty_ && impl_->threaded_solve();
}

void SparseFactorisation::set_factor_threading(FactorThreading threading) {
  impl_->set_factor_threading(threading);
}

bool SparseFactorisation::threaded_factorisation() const {
  return !empty_ && impl_->threaded_factorisation();
}

void factorize_or_throw(SparseFactorisation& f, const SparseMatrix& a, const char* what) {
  if (!f.factorize(a)) {
    throw Error(std::string(what) +
                " is singular or indefinite: the Dirichlet conditions do not prevent rigid-body "
                "motion (fix more components) or an element is inverted");
  }
}

}  // namespace partita::fem
