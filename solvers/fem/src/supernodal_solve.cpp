#include "supernodal_solve.hpp"

#include <algorithm>
#include <cstddef>
#include <numeric>

#include "omp_threads.hpp"
#include "supernodal_kernels.hpp"

namespace partita::fem::detail {
namespace {

// The levels of the cut, as shares of the factor's entries: fixed by the structure alone (never
// by the thread count), as everything that decides the order of the sums. The last level holds
// what is left (the top separators above a quarter of the work: at most three disjoint
// subtrees are that large, so it is the root's neighbourhood, a few per cent).
constexpr double kLevelLimits[] = {1.0 / 256.0, 1.0 / 32.0, 1.0 / 4.0};
constexpr int kLevels = 4;
// The last level is taken one supernode at a time: a supernode of at least this many entries
// has its diagonal triangle done by one thread and its rectangle below shared (rows forward,
// columns backward: a row's or a column's sum does not depend on who takes it), in chunks of
// kRowChunk rows or kColumnChunk columns handed out as the threads come.
constexpr double kSharedMin = 65536.0;
constexpr int kRowChunk = 256;
constexpr int kColumnChunk = 16;

inline SupernodeBlock block(const SupernodalFactor& f, int s) {
  return {f.super[s], f.super[s + 1] - f.super[s], f.pi[s + 1] - f.pi[s], f.rows + f.pi[s],
          f.values + f.px[s]};
}

}  // namespace

bool SupernodalSolve::prepare(const SupernodalFactor& f) {
  members_.clear();
  member_begin_.assign(1, 0);
  level_begin_.assign(1, 0);
  level_share_.assign(kLevels, 0.0);
  buffer_begin_.assign(1, 0);
  const int ns = f.nsuper;
  if (f.n <= 0 || ns <= 0) return false;
  const auto at = [](auto& v, int i) -> auto& {
    return v[static_cast<std::size_t>(i)];
  };
  std::vector<int> col_super(static_cast<std::size_t>(f.n), -1);
  for (int s = 0; s < ns; ++s) {
    if (f.super[s + 1] <= f.super[s]) return false;
    for (int k = f.super[s]; k < f.super[s + 1]; ++k) at(col_super, k) = s;
  }
  // elimination tree of the supernodes: the parent holds the first off-diagonal row
  std::vector<int> parent(static_cast<std::size_t>(ns), -1), first(static_cast<std::size_t>(ns));
  std::vector<int> size(static_cast<std::size_t>(ns), 1);
  std::vector<double> own(static_cast<std::size_t>(ns)), work(static_cast<std::size_t>(ns));
  std::iota(first.begin(), first.end(), 0);
  widest_ = 0;
  for (int s = 0; s < ns; ++s) {
    const SupernodeBlock b = block(f, s);
    if (b.nrow < b.ncol) return false;
    for (int i = 0; i < b.ncol; ++i)
      if (b.rows[i] != b.k1 + i) return false;
    for (int i = b.ncol + 1; i < b.nrow; ++i)
      if (b.rows[i] <= b.rows[i - 1]) return false;
    widest_ = std::max(widest_, b.nrow - b.ncol);
    at(own, s) = static_cast<double>(b.nrow) * b.ncol;
    at(work, s) += at(own, s);
    if (b.nrow > b.ncol) {
      const int p = at(col_super, b.rows[b.ncol]);
      if (p <= s) return false;  // not postordered
      at(parent, s) = p;
      at(first, p) = std::min(at(first, p), at(first, s));
      at(size, p) += at(size, s);
      at(work, p) += at(work, s);
    }
  }
  double total = 0.0;
  for (int s = 0; s < ns; ++s) {
    // postorder: a subtree is the contiguous range first .. s
    if (at(size, s) != s - at(first, s) + 1) return false;
    if (at(parent, s) < 0) total += at(work, s);
  }
  // the level of a supernode: the first whose limit its subtree's work is within (a parent's
  // level is at least its children's)
  std::vector<int> level(static_cast<std::size_t>(ns), kLevels - 1);
  for (int s = 0; s < ns; ++s)
    for (int l = 0; l < kLevels - 1; ++l)
      if (at(work, s) <= kLevelLimits[l] * total) {
        at(level, s) = l;
        break;
      }
  std::vector<int> mark(static_cast<std::size_t>(f.n), -1);
  int buffer = 0, task = 0;
  top_.clear();
  for (int s = 0; s < ns; ++s)
    if (at(level, s) == kLevels - 1) {
      top_.push_back(s);
      at(level_share_, kLevels - 1) += at(own, s) / total;
    }
  for (int l = 0; l < kLevels - 1; ++l) {
    std::vector<int> roots;
    for (int s = 0; s < ns; ++s) {
      const int p = at(parent, s);
      if (at(level, s) == l && (p < 0 || at(level, p) > l)) roots.push_back(s);
    }
    // largest first (a dynamic schedule then balances); the order is the structure's
    std::stable_sort(roots.begin(), roots.end(),
                     [&](int a, int b) { return at(work, a) > at(work, b); });
    for (const int root : roots) {
      const SupernodeBlock br = block(f, root);
      const int end = br.k1 + br.ncol;  // the columns of the task's subtree end here
      for (int i = br.ncol; i < br.nrow; ++i) at(mark, br.rows[i]) = task;
      for (int s = at(first, root); s <= root; ++s) {
        if (at(level, s) != l) continue;  // in a task of a lower level
        members_.push_back(s);
        at(level_share_, l) += at(own, s) / total;
        // a forward update stays in the task or lands on a row of the root's off-diagonal
        // pattern (the pattern of a column below the diagonal is in its parent's): checked
        const SupernodeBlock b = block(f, s);
        for (int i = b.ncol; i < b.nrow; ++i) {
          const int r = b.rows[i];
          if (r < end ? at(level, at(col_super, r)) != l : at(mark, r) != task) return false;
        }
      }
      member_begin_.push_back(static_cast<int>(members_.size()));
      buffer += br.nrow - br.ncol;
      buffer_begin_.push_back(buffer);
      ++task;
    }
    level_begin_.push_back(task);
  }
  buffer_.assign(static_cast<std::size_t>(buffer), 0.0);
  work_.assign(static_cast<std::size_t>(widest_), 0.0);
  y_.assign(static_cast<std::size_t>(f.n), 0.0);
  scratch_.clear();
  return true;
}

void SupernodalSolve::forward_task(const SupernodalFactor& f, int t, double* y, double* scratch) {
  const SupernodalKernels& k = supernodal_kernels();
  const int* m = members_.data() + member_begin_[static_cast<std::size_t>(t)];
  const int count =
      member_begin_[static_cast<std::size_t>(t) + 1] - member_begin_[static_cast<std::size_t>(t)];
  const SupernodeBlock br = block(f, m[count - 1]);
  const int end = br.k1 + br.ncol;  // rows below: in the task; from here: its root's pattern
  double* w = scratch + f.n;
  for (int i = 0; i < count; ++i) k.forward_serial(block(f, m[i]), y, w, end, scratch);
  // hand the updates that leave the task to its buffer, leave the scratch zero
  double* out = buffer_.data() + buffer_begin_[static_cast<std::size_t>(t)];
  for (int i = br.ncol; i < br.nrow; ++i) {
    const int r = br.rows[i];
    out[i - br.ncol] = scratch[r];
    scratch[r] = 0.0;
  }
}

void SupernodalSolve::backward_task(const SupernodalFactor& f, int t, double* y, double* g) {
  const SupernodalKernels& k = supernodal_kernels();
  const int* m = members_.data() + member_begin_[static_cast<std::size_t>(t)];
  const int count =
      member_begin_[static_cast<std::size_t>(t) + 1] - member_begin_[static_cast<std::size_t>(t)];
  for (int i = count - 1; i >= 0; --i) k.backward_serial(block(f, m[i]), y, g);
}

void SupernodalSolve::solve(const SupernodalFactor& f, const double* b, double* x) {
  const int threads = max_threads();
  const std::size_t per_thread = static_cast<std::size_t>(f.n) + static_cast<std::size_t>(widest_);
  if (scratch_.size() < static_cast<std::size_t>(threads)) scratch_.resize(threads);
  for (auto& s : scratch_)
    if (s.size() != per_thread) s.assign(per_thread, 0.0);
  double* y = y_.data();
  const int n = f.n;
  const int nlevels = levels();
  const SupernodalKernels& k = supernodal_kernels();
#pragma omp parallel
  {
    double* scratch = scratch_[static_cast<std::size_t>(thread_id())].data();
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) y[i] = b[f.perm[i]];
    // ---- forward, L y = P b: level by level, a level's buffers added once it is done
    for (int l = 0; l < nlevels; ++l) {
      const int t0 = level_begin_[static_cast<std::size_t>(l)];
      const int t1 = level_begin_[static_cast<std::size_t>(l) + 1];
#pragma omp for schedule(dynamic, 1)
      for (int t = t0; t < t1; ++t) forward_task(f, t, y, scratch);
#pragma omp single
      for (int t = t0; t < t1; ++t) {
        const int root = members_[static_cast<std::size_t>(member_begin_[t + 1]) - 1];
        const SupernodeBlock br = block(f, root);
        const double* in = buffer_.data() + buffer_begin_[static_cast<std::size_t>(t)];
        for (int i = br.ncol; i < br.nrow; ++i) y[br.rows[i]] -= in[i - br.ncol];
      }
    }
    // the last level: one supernode after the other, a large one shared
    const int ntop = static_cast<int>(top_.size());
    for (int q = 0; q < ntop; ++q) {
      const SupernodeBlock bq = block(f, top_[static_cast<std::size_t>(q)]);
      if (static_cast<double>(bq.nrow) * bq.ncol < kSharedMin) {
#pragma omp single
        k.forward_serial(bq, y, work_.data(), n, nullptr);
        continue;
      }
#pragma omp single
      k.forward_diagonal(bq, y);
      const int chunks = (bq.nrow - bq.ncol + kRowChunk - 1) / kRowChunk;
#pragma omp for schedule(dynamic, 1)
      for (int c = 0; c < chunks; ++c) {
        const int r0 = bq.ncol + c * kRowChunk, r1 = std::min(bq.nrow, r0 + kRowChunk);
        double* w = scratch + n;
        k.forward_offdiagonal(bq, y, r0, r1, w);
        for (int i = r0; i < r1; ++i) y[bq.rows[i]] -= w[i - r0];
      }
    }
    // ---- backward, L^T z = y: the last level from the root down, then the tasks' levels
    for (int q = ntop - 1; q >= 0; --q) {
      const SupernodeBlock bq = block(f, top_[static_cast<std::size_t>(q)]);
      if (static_cast<double>(bq.nrow) * bq.ncol < kSharedMin) {
#pragma omp single
        k.backward_serial(bq, y, work_.data());
        continue;
      }
      const int m = bq.nrow - bq.ncol;
      double* g = work_.data();
#pragma omp for schedule(static)
      for (int i = 0; i < m; ++i) g[i] = y[bq.rows[bq.ncol + i]];
      const int chunks = (bq.ncol + kColumnChunk - 1) / kColumnChunk;
#pragma omp for schedule(dynamic, 1)
      for (int c = 0; c < chunks; ++c)
        k.backward_offdiagonal(bq, g, y, c * kColumnChunk,
                               std::min(bq.ncol, (c + 1) * kColumnChunk));
#pragma omp single
      k.backward_diagonal(bq, y);
    }
    for (int l = nlevels - 1; l >= 0; --l) {
      const int t0 = level_begin_[static_cast<std::size_t>(l)];
      const int t1 = level_begin_[static_cast<std::size_t>(l) + 1];
#pragma omp for schedule(dynamic, 1)
      for (int t = t0; t < t1; ++t) backward_task(f, t, y, scratch + n);
    }
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) x[f.perm[i]] = y[i];
  }
}

}  // namespace partita::fem::detail
