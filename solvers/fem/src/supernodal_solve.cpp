#include "supernodal_solve.hpp"

#include "supernodal_kernels.hpp"

#include <algorithm>
#include <cstddef>
#include <numeric>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::fem::detail {
namespace {

// Fixed by the structure alone (never by the thread count), as everything that decides the
// order of the sums:
constexpr double kTaskShare = 1.0 / 64.0;  // a task: a whole subtree with at most this share
constexpr long kParallelMin = 65536;       // entries below which a top supernode is one thread's

int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
int thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}
int team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

using Block = SupernodeBlock;
constexpr int kBlock = kSupernodeBlock;

inline Block block(const SupernodalFactor& f, int s) {
  return {f.super[s], f.super[s + 1] - f.super[s], f.pi[s + 1] - f.pi[s], f.rows + f.pi[s],
          f.values + f.px[s]};
}

}  // namespace

bool SupernodalSolve::prepare(const SupernodalFactor& f) {
  task_first_.clear();
  task_root_.clear();
  task_buffer_begin_.clear();
  top_.clear();
  top_triangle_ = 0.0;
  const int ns = f.nsuper;
  if (f.n <= 0 || ns <= 0) return false;
  std::vector<int> col_super(static_cast<std::size_t>(f.n), -1);
  for (int s = 0; s < ns; ++s) {
    if (f.super[s + 1] <= f.super[s]) return false;
    for (int k = f.super[s]; k < f.super[s + 1]; ++k) col_super[static_cast<std::size_t>(k)] = s;
  }
  // elimination tree of the supernodes: the parent holds the first off-diagonal row
  std::vector<int> parent(static_cast<std::size_t>(ns), -1), first(static_cast<std::size_t>(ns));
  std::vector<double> work(static_cast<std::size_t>(ns));
  std::iota(first.begin(), first.end(), 0);
  std::vector<int> size(static_cast<std::size_t>(ns), 1);
  for (int s = 0; s < ns; ++s) {
    const Block b = block(f, s);
    if (b.nrow < b.ncol) return false;
    for (int i = 0; i < b.ncol; ++i)
      if (b.rows[i] != b.k1 + i) return false;
    for (int i = b.ncol + 1; i < b.nrow; ++i)
      if (b.rows[i] <= b.rows[i - 1]) return false;
    work[static_cast<std::size_t>(s)] += static_cast<double>(b.nrow) * b.ncol;
    if (b.nrow > b.ncol) {
      const int p = col_super[static_cast<std::size_t>(b.rows[b.ncol])];
      if (p <= s) return false;  // not postordered
      parent[static_cast<std::size_t>(s)] = p;
      first[static_cast<std::size_t>(p)] =
          std::min(first[static_cast<std::size_t>(p)], first[static_cast<std::size_t>(s)]);
      size[static_cast<std::size_t>(p)] += size[static_cast<std::size_t>(s)];
      work[static_cast<std::size_t>(p)] += work[static_cast<std::size_t>(s)];
    }
  }
  double total = 0.0;
  for (int s = 0; s < ns; ++s) {
    // postorder: a subtree is the contiguous range first .. s
    if (size[static_cast<std::size_t>(s)] != s - first[static_cast<std::size_t>(s)] + 1)
      return false;
    if (parent[static_cast<std::size_t>(s)] < 0) total += work[static_cast<std::size_t>(s)];
  }
  // the cut: subtrees of at most kTaskShare of the work are tasks, the rest is the top
  const double limit = kTaskShare * total;
  std::vector<char> is_top(static_cast<std::size_t>(ns), 0);
  double top_work = 0.0;
  for (int s = 0; s < ns; ++s) {
    if (work[static_cast<std::size_t>(s)] > limit) {
      is_top[static_cast<std::size_t>(s)] = 1;
      top_.push_back(s);
      const Block b = block(f, s);
      top_work += static_cast<double>(b.nrow) * b.ncol;
      top_triangle_ += 0.5 * b.ncol * (b.ncol + 1.0);
    }
  }
  // runs of consecutive small top supernodes form one step
  top_steps_.clear();
  for (const int s : top_) {
    const Block b = block(f, s);
    const bool shared = static_cast<long>(b.nrow) * b.ncol >= kParallelMin;
    if (!shared && !top_steps_.empty() && !top_steps_.back().shared &&
        top_steps_.back().last + 1 == s) {
      top_steps_.back().last = s;
      continue;
    }
    top_steps_.push_back({s, s, shared});
  }
  std::vector<int> roots;
  for (int s = 0; s < ns; ++s) {
    const int p = parent[static_cast<std::size_t>(s)];
    if (!is_top[static_cast<std::size_t>(s)] && (p < 0 || is_top[static_cast<std::size_t>(p)]))
      roots.push_back(s);
  }
  // largest first (a dynamic schedule then balances); the order is the structure's
  std::stable_sort(roots.begin(), roots.end(), [&](int a, int b) {
    return work[static_cast<std::size_t>(a)] > work[static_cast<std::size_t>(b)];
  });
  // every forward update that leaves a task lands on a row of its root's off-diagonal pattern
  // (the pattern of a column below the diagonal is in its parent's): checked, not assumed
  std::vector<int> mark(static_cast<std::size_t>(f.n), -1);
  int buffer = 0;
  for (std::size_t t = 0; t < roots.size(); ++t) {
    const int root = roots[t], lo = first[static_cast<std::size_t>(root)];
    const Block br = block(f, root);
    const int end = br.k1 + br.ncol;
    for (int i = br.ncol; i < br.nrow; ++i)
      mark[static_cast<std::size_t>(br.rows[i])] = static_cast<int>(t);
    for (int s = lo; s <= root; ++s) {
      const Block b = block(f, s);
      for (int i = b.ncol; i < b.nrow; ++i)
        if (b.rows[i] >= end && mark[static_cast<std::size_t>(b.rows[i])] != static_cast<int>(t))
          return false;
    }
    task_first_.push_back(lo);
    task_root_.push_back(root);
    task_buffer_begin_.push_back(buffer);
    buffer += br.nrow - br.ncol;
  }
  task_buffer_begin_.push_back(buffer);
  buffer_.assign(static_cast<std::size_t>(buffer), 0.0);
  int widest = 0;
  for (int s = 0; s < ns; ++s) widest = std::max(widest, f.pi[s + 1] - f.pi[s]);
  work_.assign(static_cast<std::size_t>(widest), 0.0);
  y_.assign(static_cast<std::size_t>(f.n), 0.0);
  scratch_.clear();
  top_share_ = total > 0.0 ? top_work / total : 0.0;
  top_triangle_ = total > 0.0 ? top_triangle_ / total : 0.0;
  return true;
}

void SupernodalSolve::forward_task(const SupernodalFactor& f, int t, double* y, double* scratch) {
  const SupernodalKernels& k = supernodal_kernels();
  const int lo = task_first_[static_cast<std::size_t>(t)];
  const int root = task_root_[static_cast<std::size_t>(t)];
  const Block br = block(f, root);
  const int end = br.k1 + br.ncol;  // the task's columns are [super[lo], end)
  double* w = scratch + f.n;
  for (int s = lo; s <= root; ++s) k.forward_serial(block(f, s), y, w, end, scratch);
  // hand the updates that leave the task to its buffer, leave the scratch zero
  double* out = buffer_.data() + task_buffer_begin_[static_cast<std::size_t>(t)];
  for (int i = br.ncol; i < br.nrow; ++i) {
    const int r = br.rows[i];
    out[i - br.ncol] = scratch[r];
    scratch[r] = 0.0;
  }
}

void SupernodalSolve::backward_task(const SupernodalFactor& f, int t, double* y, double* g) {
  const SupernodalKernels& k = supernodal_kernels();
  const int lo = task_first_[static_cast<std::size_t>(t)];
  const int root = task_root_[static_cast<std::size_t>(t)];
  for (int s = root; s >= lo; --s) k.backward_serial(block(f, s), y, g);
}

namespace {
// part `part` of `parts` of the range [begin, end), boundaries on multiples of 8 from begin
inline void share(int begin, int end, int part, int parts, int& a, int& b) {
  const int units = (end - begin + 7) / 8;
  a = std::min(end, begin + 8 * static_cast<int>(static_cast<long>(units) * part / parts));
  b = std::min(end, begin + 8 * static_cast<int>(static_cast<long>(units) * (part + 1) / parts));
}
}  // namespace

void SupernodalSolve::solve(const SupernodalFactor& f, const double* b, double* x) {
  const SupernodalKernels& k = supernodal_kernels();
  const int threads = max_threads();
  const std::size_t per_thread = static_cast<std::size_t>(f.n) + work_.size();
  if (scratch_.size() < static_cast<std::size_t>(threads)) scratch_.resize(threads);
  for (auto& s : scratch_)
    if (s.size() != per_thread) s.assign(per_thread, 0.0);
  double* y = y_.data();
  const int n = f.n;
  const int ntasks = tasks();
#pragma omp parallel
  {
    const int tid = thread_id(), nth = team_size();
    double* scratch = scratch_[static_cast<std::size_t>(tid)].data();
    double* w = scratch + n;  // nrow - ncol doubles of any supernode
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) y[i] = b[f.perm[i]];
      // ---- forward, L y = P b: the tasks, then their updates to the top, then the top
#pragma omp for schedule(dynamic, 1)
    for (int t = 0; t < ntasks; ++t) forward_task(f, t, y, scratch);
#pragma omp single
    for (int t = 0; t < ntasks; ++t) {
      const Block br = block(f, task_root_[static_cast<std::size_t>(t)]);
      const double* in = buffer_.data() + task_buffer_begin_[static_cast<std::size_t>(t)];
      for (int i = br.ncol; i < br.nrow; ++i) y[br.rows[i]] -= in[i - br.ncol];
    }
    // The top supernodes in order; runs of small ones by one thread, a large one's diagonal
    // triangle by one thread and its rectangle below shared: a row's (a column's) sums do not
    // depend on how the rows (columns) are shared. Few barriers: a thread that the system
    // deschedules holds up every barrier.
    const int nsteps = static_cast<int>(top_steps_.size());
    for (int q = 0; q < nsteps; ++q) {
      const TopStep& st = top_steps_[static_cast<std::size_t>(q)];
      if (!st.shared) {
#pragma omp single
        for (int s = st.first; s <= st.last; ++s)
          k.forward_serial(block(f, s), y, work_.data(), n, nullptr);
        continue;
      }
      const Block bq = block(f, st.first);
#pragma omp single
      for (int j0 = 0; j0 < bq.ncol; j0 += kBlock) {
        const int j1 = std::min(bq.ncol, j0 + kBlock);
        k.forward_triangle(bq, y, j0, j1);
        k.forward_rows_below(bq, y, j0, j1, j1, bq.ncol);
      }
      int r0, r1;
      share(bq.ncol, bq.nrow, tid, nth, r0, r1);
      if (r0 < r1) {
        k.forward_offdiagonal(bq, y, r0, r1, w);
        for (int i = r0; i < r1; ++i) y[bq.rows[i]] -= w[i - r0];
      }
#pragma omp barrier
    }
    // ---- backward, L^T z = y: the top from the root down, then the tasks
    for (int q = nsteps - 1; q >= 0; --q) {
      const TopStep& st = top_steps_[static_cast<std::size_t>(q)];
      if (!st.shared) {
#pragma omp single
        for (int s = st.last; s >= st.first; --s) k.backward_serial(block(f, s), y, work_.data());
        continue;
      }
      const Block bq = block(f, st.first);
      const int m = bq.nrow - bq.ncol;
      double* g = work_.data();
      double* ys = y + bq.k1;
#pragma omp for schedule(static)
      for (int i = 0; i < m; ++i) g[i] = y[bq.rows[bq.ncol + i]];
        // pairs of columns, as the serial kernel takes them
#pragma omp for schedule(static)
      for (int j = 0; j < bq.ncol; j += 2)
        k.columns_dot(bq, g, bq.ncol, m, ys, j, std::min(bq.ncol, j + 2));
      const int blocks = (bq.ncol + kBlock - 1) / kBlock;
#pragma omp single
      for (int kb = blocks - 1; kb >= 0; --kb) {
        const int j0 = kb * kBlock, j1 = std::min(bq.ncol, j0 + kBlock);
        k.backward_triangle(bq, y, j0, j1);
        k.columns_dot(bq, ys + j0, j0, j1 - j0, ys, 0, j0);
      }
    }
#pragma omp for schedule(dynamic, 1)
    for (int t = 0; t < ntasks; ++t) backward_task(f, t, y, w);
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) x[f.perm[i]] = y[i];
  }
}

}  // namespace partita::fem::detail
