#pragma once
// A threaded solve with a supernodal Cholesky factor L L^T = P A P^T (CHOLMOD's supernodal
// storage, read in place): forward L y = P b and backward L^T z = y, x = P^T z.
//
// Why: a transient step with a factorised K_eff is two triangular solves, and these are
// memory-bound (the whole factor is read twice a step: 650 MB at 263k dofs). One core streams
// about half of what two cores do, and CHOLMOD's solve uses one (OpenBLAS serial, for
// determinism). This solve cuts the supernodal elimination tree at a few levels of subtree work
// (1/256, 1/32, 1/4 of the factor's entries): the tasks of a level are the largest subtrees
// below its limit, less the tasks of the lower levels, and are independent of each other. A
// thread takes a whole task; a forward update that leaves a task goes into the task's own
// buffer, and the buffers are added to the ancestors in a fixed order once the level is done.
// What is left (the top separators, whose subtrees hold over a quarter of the work) is taken one
// supernode at a time, the rectangle below a large one's triangle shared by rows or columns.
// So a solve has few barriers (a thread that the system deschedules holds up each one), and the
// cut, the tasks and every sum's order depend on the factor's structure only, never on the number
// of threads or on which thread runs a task: the solution is the same bit for bit on any thread
// count (it differs from CHOLMOD's own solve by round-off).
#include <vector>

namespace partita::fem::detail {

// The supernodal factor as CHOLMOD stores it (itype int, real double): supernode s holds columns
// super[s] .. super[s+1]-1; its row indices are rows[pi[s] .. pi[s+1]) (sorted, the first ones
// the supernode's own columns); its values a column-major nrow x ncol block at values + px[s].
// perm[k]: the row of A that is row k of P A P^T.
struct SupernodalFactor {
  int n = 0, nsuper = 0;
  const int *super = nullptr, *pi = nullptr, *px = nullptr, *rows = nullptr, *perm = nullptr;
  const double* values = nullptr;
};

class SupernodalSolve {
 public:
  // Builds the schedule from the factor's structure (the values may change later: the schedule
  // stays valid while the structure is the same). Returns false when the structure does not have
  // the properties the schedule relies on (then use another solve).
  bool prepare(const SupernodalFactor& f);
  // x = A^-1 b with the factor's current values. b and x of size n, may not alias. Uses the
  // OpenMP threads available (omp_get_max_threads()); no allocation after the first call.
  void solve(const SupernodalFactor& f, const double* b, double* x);

  // the levels of tasks (the last level, taken supernode by supernode, not counted)
  int levels() const { return static_cast<int>(level_begin_.size()) - 1; }
  int tasks(int level) const { return level_begin_[level + 1] - level_begin_[level]; }
  int top_supernodes() const { return static_cast<int>(top_.size()); }
  // share of the factor's entries in the tasks of a level (levels(): the last level's)
  double share(int level) const { return level_share_[static_cast<std::size_t>(level)]; }

 private:
  void forward_task(const SupernodalFactor& f, int t, double* y, double* scratch);
  void backward_task(const SupernodalFactor& f, int t, double* y, double* g);

  // task t: supernodes members_[member_begin_[t] .. member_begin_[t+1]) (ascending), the last
  // one its root; the tasks of level l: level_begin_[l] .. level_begin_[l+1]
  std::vector<int> members_, member_begin_, level_begin_;
  std::vector<int> buffer_begin_;  // task t's buffer: buffer_[begin[t] .. begin[t+1])
  std::vector<double> buffer_;     // forward updates leaving a task, per task
  std::vector<double> level_share_;
  std::vector<int> top_;                      // the last level's supernodes, ascending
  std::vector<double> work_;                  // the last level's gathered rows
  std::vector<std::vector<double>> scratch_;  // per thread: n (zero between tasks) + work space
  std::vector<double> y_;                     // the permuted right-hand side and solution
  int widest_ = 0;                            // most off-diagonal rows of a supernode
};

}  // namespace partita::fem::detail
