#pragma once
// A threaded solve with a supernodal Cholesky factor L L^T = P A P^T (CHOLMOD's supernodal
// storage, read in place): forward L y = P b and backward L^T z = y, x = P^T z.
//
// Why: a transient step with a factorised K_eff is two triangular solves, and these are
// memory-bound (the whole factor is read twice a step: 650 MB at 263k dofs). One core streams
// about half of what two cores do, and CHOLMOD's solve uses one (OpenBLAS serial, for
// determinism). This solve splits the supernodal elimination tree:
//  - the subtrees below a cut are independent tasks (one thread each; a forward update that
//    leaves a subtree goes into the task's own buffer, added to the ancestors afterwards in
//    task order);
//  - the supernodes above the cut (the top separators of a nested-dissection ordering, few and
//    large) are taken one at a time, their rows or columns shared among the threads.
// Determinism: the cut, the tasks and every sum's order depend on the factor's structure only,
// never on the number of threads or on which thread runs a task, so the solution is the same bit
// for bit on any thread count (it differs from CHOLMOD's own solve by round-off).
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

  int tasks() const { return static_cast<int>(task_root_.size()); }
  int top_supernodes() const { return static_cast<int>(top_.size()); }
  // share of the factor's entries in the top part (taken one supernode at a time)
  double top_share() const { return top_share_; }
  // share of the factor's entries in the diagonal triangles of the top supernodes
  double top_triangle_share() const { return top_triangle_; }

 private:
  void forward_task(const SupernodalFactor& f, int t, double* y, double* scratch);
  void backward_task(const SupernodalFactor& f, int t, double* y, double* g);

  std::vector<int> task_first_, task_root_;  // task t: supernodes task_first_[t] .. task_root_[t]
  std::vector<int> task_buffer_begin_;       // task t's buffer: buffer_[begin[t] .. begin[t+1])
  std::vector<int> top_;                     // the supernodes above the cut, ascending
  struct TopStep {
    int first, last;  // supernodes first .. last (ascending) of the top
    bool shared;      // one large supernode shared by the threads, else a run for one thread
  };
  std::vector<TopStep> top_steps_;
  std::vector<double> buffer_;                // forward updates leaving a task, per task
  std::vector<std::vector<double>> scratch_;  // per thread, size n, zero between tasks
  std::vector<double> y_, work_;              // permuted right-hand side; top-part work space
  double top_share_ = 0.0, top_triangle_ = 0.0;
};

}  // namespace partita::fem::detail
