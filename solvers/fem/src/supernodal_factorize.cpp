#include "supernodal_factorize.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstring>

#include "omp_threads.hpp"
#include "supernodal_kernels.hpp"

namespace partita::fem::detail {
namespace {

// A supernode shares its rows among the threads when it has at least 2 blocks of kRowBlock rows
// and at least kSharedMinWork flops (its updates and its own factorisation): below, one thread
// does it in one piece. Both are structure only, so the bits do not depend on the thread count.
constexpr int kRowBlock = 128;
constexpr double kSharedMinWork = 4e6;

template <class V>
auto& at(V& v, std::int64_t i) {
  return v[static_cast<std::size_t>(i)];
}

}  // namespace

bool SupernodalFactorize::prepare(const SupernodalFactor& f, const SparsePattern& a) {
  n_ = f.n;
  nsuper_ = f.nsuper;
  const int ns = f.nsuper;
  if (f.n <= 0 || ns <= 0 || a.n != f.n) return false;
  col_super_.assign(static_cast<std::size_t>(f.n), -1);
  super_begin_.assign(f.super, f.super + ns + 1);
  for (int s = 0; s < ns; ++s) {
    if (f.super[s + 1] <= f.super[s]) return false;
    for (int k = f.super[s]; k < f.super[s + 1]; ++k) at(col_super_, k) = s;
  }
  if (f.super[ns] != f.n) return false;
  // the tree, and the updates: descendant d's rows in the columns of s form one run [p1, p2)
  parent_.assign(static_cast<std::size_t>(ns), -1);
  first_.resize(static_cast<std::size_t>(ns));
  for (int s = 0; s < ns; ++s) at(first_, s) = s;
  std::vector<int> size(static_cast<std::size_t>(ns), 1), count(static_cast<std::size_t>(ns), 0);
  widest_ = 0;
  for (int d = 0; d < ns; ++d) {
    const int ncol = f.super[d + 1] - f.super[d], nrow = f.pi[d + 1] - f.pi[d];
    const int* rows = f.rows + f.pi[d];
    if (nrow < ncol) return false;
    for (int i = 0; i < ncol; ++i)
      if (rows[i] != f.super[d] + i) return false;
    for (int i = ncol + 1; i < nrow; ++i)
      if (rows[i] <= rows[i - 1]) return false;
    if (nrow > 0 && rows[nrow - 1] >= f.n) return false;
    widest_ = std::max(widest_, nrow);
    for (int i = ncol; i < nrow;) {
      const int s = at(col_super_, rows[i]);
      if (s <= d) return false;  // not postordered
      while (i < nrow && at(col_super_, rows[i]) == s) ++i;
      ++at(count, s);
    }
    if (nrow > ncol) {
      const int p = at(col_super_, rows[ncol]);
      at(parent_, d) = p;
      at(first_, p) = std::min(at(first_, p), at(first_, d));
      at(size, p) += at(size, d);
    }
  }
  for (int s = 0; s < ns; ++s)
    if (at(size, s) != s - at(first_, s) + 1) return false;  // a subtree must be a range
  update_begin_.assign(static_cast<std::size_t>(ns) + 1, 0);
  for (int s = 0; s < ns; ++s) at(update_begin_, s + 1) = at(update_begin_, s) + at(count, s);
  updates_.resize(static_cast<std::size_t>(update_begin_.back()));
  std::vector<int> next(update_begin_.begin(), update_begin_.end() - 1);
  // work (flops): the own factorisation c^3/3 + (m - c) c^2, and each update received
  // 2 c_d (m_d - p1) (p2 - p1); d ascending, so every list is in ascending order
  subtree_work_.assign(static_cast<std::size_t>(ns), 0.0);
  for (int d = 0; d < ns; ++d) {
    const int ncol = f.super[d + 1] - f.super[d], nrow = f.pi[d + 1] - f.pi[d];
    const int* rows = f.rows + f.pi[d];
    at(subtree_work_, d) += static_cast<double>(ncol) * ncol * ncol / 3.0 +
                            static_cast<double>(nrow - ncol) * ncol * ncol;
    for (int i = ncol; i < nrow;) {
      const int s = at(col_super_, rows[i]), p1 = i;
      while (i < nrow && at(col_super_, rows[i]) == s) ++i;
      at(updates_, at(next, s)++) = {d, p1, i};
      at(subtree_work_, s) += 2.0 * ncol * static_cast<double>(nrow - p1) * (i - p1);
    }
  }
  shared_.assign(static_cast<std::size_t>(ns), 0);
  for (int s = 0; s < ns; ++s) {
    const int nrow = f.pi[s + 1] - f.pi[s];
    at(shared_, s) = nrow >= 2 * kRowBlock && at(subtree_work_, s) >= kSharedMinWork;
  }
  // the largest update block a thread computes: rows of d from the target's first column on (at
  // most a block of kRowBlock of them where the target shares its rows) times the target's
  // columns that d holds
  work_size_ = 0;
  for (int s = 0; s < ns; ++s)
    for (int u = at(update_begin_, s); u < at(update_begin_, s + 1); ++u) {
      const Update& up = at(updates_, u);
      const int rows = f.pi[up.d + 1] - f.pi[up.d] - up.p1;
      const std::size_t m =
          static_cast<std::size_t>(at(shared_, s) ? std::min(rows, kRowBlock) : rows);
      work_size_ = std::max(work_size_, m * static_cast<std::size_t>(up.p2 - up.p1));
    }
  // subtree work (children before parents) and the children lists
  total_work_ = 0.0;
  std::vector<int> nchild(static_cast<std::size_t>(ns), 0);
  for (int s = 0; s < ns; ++s) {
    const int p = at(parent_, s);
    if (p >= 0) {
      at(subtree_work_, p) += at(subtree_work_, s);
      ++at(nchild, p);
    } else {
      total_work_ += at(subtree_work_, s);
    }
  }
  child_begin_.assign(static_cast<std::size_t>(ns) + 1, 0);
  for (int s = 0; s < ns; ++s) at(child_begin_, s + 1) = at(child_begin_, s) + at(nchild, s);
  children_.resize(static_cast<std::size_t>(child_begin_.back()));
  std::vector<int> fill(child_begin_.begin(), child_begin_.end() - 1);
  for (int s = 0; s < ns; ++s)
    if (at(parent_, s) >= 0) at(children_, at(fill, at(parent_, s))++) = s;

  // where A's lower-triangle entries land: (max(i, j), min(i, j)) of P A P^T, in the supernode
  // of column min(i, j); grouped by supernode (assembled just before the supernode is worked on)
  std::vector<int> pinv(static_cast<std::size_t>(f.n));
  for (int k = 0; k < f.n; ++k) {
    if (f.perm[k] < 0 || f.perm[k] >= f.n) return false;
    at(pinv, f.perm[k]) = k;
  }
  begin_.assign(a.begin, a.begin + a.n + 1);
  index_.assign(a.index, a.index + a.begin[a.n]);
  // counted by supernode, then filled in A's order, then each supernode's entries resolved with
  // its rows' map (no search)
  entry_begin_.assign(static_cast<std::size_t>(ns) + 1, 0);
  for (int j = 0; j < a.n; ++j)
    for (int p = a.begin[j]; p < a.begin[j + 1]; ++p) {
      const int r = a.index[p];
      if (r < j) continue;  // upper triangle: ignored
      if (r >= a.n) return false;
      ++at(entry_begin_, at(col_super_, std::min(at(pinv, r), at(pinv, j))) + 1);
    }
  for (int s = 0; s < ns; ++s) at(entry_begin_, s + 1) += at(entry_begin_, s);
  const std::size_t entries = static_cast<std::size_t>(entry_begin_.back());
  src_.resize(entries);
  dst_.resize(entries);
  std::vector<int> lo_of(entries), hi_of(entries);
  {
    std::vector<std::int64_t> put(entry_begin_.begin(), entry_begin_.end() - 1);
    for (int j = 0; j < a.n; ++j)
      for (int p = a.begin[j]; p < a.begin[j + 1]; ++p) {
        const int r = a.index[p];
        if (r < j) continue;
        const int pi = at(pinv, r), pj = at(pinv, j);
        const int lo = std::min(pi, pj);
        const std::int64_t q = at(put, at(col_super_, lo))++;
        at(src_, q) = p;
        at(lo_of, q) = lo;
        at(hi_of, q) = std::max(pi, pj);
      }
  }
  std::vector<int> map(static_cast<std::size_t>(f.n)), mark(static_cast<std::size_t>(f.n), -1);
  for (int s = 0; s < ns; ++s) {
    const int* rows = f.rows + f.pi[s];
    const int nrow = f.pi[s + 1] - f.pi[s];
    for (int i = 0; i < nrow; ++i) {
      at(map, rows[i]) = i;
      at(mark, rows[i]) = s;
    }
    for (std::int64_t q = at(entry_begin_, s); q < at(entry_begin_, s + 1); ++q) {
      const int hi = at(hi_of, q);
      if (at(mark, hi) != s) return false;  // outside L's pattern
      at(dst_, q) = f.px[s] + (at(lo_of, q) - f.super[s]) * nrow + at(map, hi);
    }
  }
  scratch_.clear();
  return true;
}

bool SupernodalFactorize::same_pattern(const SparsePattern& a) const {
  if (a.n != n_ || begin_.size() != static_cast<std::size_t>(a.n) + 1) return false;
  return std::equal(begin_.begin(), begin_.end(), a.begin) &&
         std::equal(index_.begin(), index_.end(), a.index);
}

int SupernodalFactorize::factorize(const SupernodalFactor& f, const double* ax, double* values) {
  ax_ = ax;
  const int threads = max_threads();
  if (scratch_.size() < static_cast<std::size_t>(threads))
    scratch_.resize(static_cast<std::size_t>(threads));
  for (auto& sc : scratch_) {
    if (sc.map.size() != static_cast<std::size_t>(n_))
      sc.map.assign(static_cast<std::size_t>(n_), 0);
    if (sc.rel.size() < static_cast<std::size_t>(widest_))
      sc.rel.assign(static_cast<std::size_t>(widest_), 0);
    if (sc.c.size() < work_size_) sc.c.assign(work_size_, 0.0);
    if (sc.pack.size() != static_cast<std::size_t>(kFactorPackSize))
      sc.pack.assign(static_cast<std::size_t>(kFactorPackSize), 0.0);
    sc.owner = -1;  // the values of the map are the last factorisation's: refilled on first use
  }
  failed_.store(false);
  failed_column_ = -1;
  if (threads <= 1) {
    for (int s = 0; s < nsuper_ && !failed_.load(std::memory_order_relaxed); ++s)
      supernode(f, values, s);
  } else {
    // tasks: the subtrees of at least 1/(8 threads) of the work; smaller ones run in one piece
    const double task_min = total_work_ / (8.0 * threads);
#pragma omp parallel
#pragma omp single
    {
      for (int s = 0; s < nsuper_; ++s)
        if (at(parent_, s) < 0) {
#pragma omp task firstprivate(s) untied
          subtree(f, values, s, task_min);
        }
    }
  }
  return failed_.load() ? failed_column_ : -1;
}

void SupernodalFactorize::subtree(const SupernodalFactor& f, double* values, int s,
                                  double task_min) {
  if (failed_.load(std::memory_order_relaxed)) return;
  if (at(subtree_work_, s) < task_min) {
    for (int t = at(first_, s); t <= s; ++t) supernode(f, values, t);
    return;
  }
  const int c0 = at(child_begin_, s), c1 = at(child_begin_, s + 1);
  if (c1 - c0 == 1) {
    subtree(f, values, at(children_, c0), task_min);  // a chain: no task needed
  } else {
    for (int c = c0; c < c1; ++c) {
      const int child = at(children_, c);
#pragma omp task firstprivate(child) untied
      subtree(f, values, child, task_min);
    }
#pragma omp taskwait
  }
  supernode(f, values, s);
}

void SupernodalFactorize::supernode(const SupernodalFactor& f, double* values, int s) {
  if (failed_.load(std::memory_order_relaxed)) return;
  const int ncol = f.super[s + 1] - f.super[s], nrow = f.pi[s + 1] - f.pi[s];
  // assemble: the block zeroed, A's entries put in
  double* ls = values + f.px[s];
  std::memset(ls, 0,
              sizeof(double) * static_cast<std::size_t>(nrow) * static_cast<std::size_t>(ncol));
  for (std::int64_t k = at(entry_begin_, s); k < at(entry_begin_, s + 1); ++k)
    values[at(dst_, k)] = ax_[at(src_, k)];
  const FactorKernels& k = factor_kernels();
  if (!at(shared_, s)) {
    update_rows(f, values, s, 0, nrow);
    fail_at(s, k.panel_factor(ncol, ls, nrow, nrow, pack()));
    return;
  }
  const int blocks = (nrow + kRowBlock - 1) / kRowBlock;
#pragma omp taskloop grainsize(1) untied
  for (int b = 0; b < blocks; ++b)
    update_rows(f, values, s, b * kRowBlock, std::min(nrow, (b + 1) * kRowBlock));
  if (fail_at(s, k.panel_factor(ncol, ls, nrow, ncol, pack()))) return;
  const int below = (nrow - ncol + kRowBlock - 1) / kRowBlock;
#pragma omp taskloop grainsize(1) untied
  for (int b = 0; b < below; ++b)
    k.panel_solve_rows(ncol, ls, nrow, ncol + b * kRowBlock,
                       std::min(nrow, ncol + (b + 1) * kRowBlock), pack());
}

// Rows [r0, r1) of supernode s (local rows) receive every descendant's update:
//   L_s(r, c) -= sum_k L_d(r, k) L_d(c, k)   for the rows r and columns c of s that d holds,
// r >= c; the descendants in ascending order, each one product over its rows in [r0, r1).
void SupernodalFactorize::update_rows(const SupernodalFactor& f, double* values, int s, int r0,
                                      int r1) {
  Scratch& sc = at(scratch_, thread_id());
  const int nrow = f.pi[s + 1] - f.pi[s];
  const int* rows = f.rows + f.pi[s];
  int* map = sc.map.data();
  if (sc.owner != s) {
    for (int i = 0; i < nrow; ++i) map[rows[i]] = i;
    sc.owner = s;
  }
  double* ls = values + f.px[s];
  double* c = sc.c.data();
  int* rel = sc.rel.data();
  const FactorKernels& k = factor_kernels();
  for (int u = at(update_begin_, s); u < at(update_begin_, s + 1); ++u) {
    const Update& up = at(updates_, u);
    const int d = up.d, p1 = up.p1, p2 = up.p2;
    const int ncol_d = f.super[d + 1] - f.super[d], nrow_d = f.pi[d + 1] - f.pi[d];
    const int* rows_d = f.rows + f.pi[d];
    // d's rows [p1, nrow_d) are rows of s, ascending: those in [r0, r1) are [q0, q1)
    const auto below = [&](int limit) {
      int lo = p1, hi = nrow_d;
      while (lo < hi) {
        const int mid = lo + (hi - lo) / 2;
        if (map[rows_d[mid]] < limit)
          lo = mid + 1;
        else
          hi = mid;
      }
      return lo;
    };
    const int q0 = r0 == 0 ? p1 : below(r0), q1 = r1 == nrow ? nrow_d : below(r1);
    if (q0 >= q1) continue;
    // the columns of s that d holds, up to the chunk's last row (the part above is not needed)
    const int m = q1 - q0, n = std::min(p2, q1) - p1;
    const double* ld = values + f.px[d];
    // c = -L_d(q0..q1) L_d(p1..p1+n)^T, then added where it belongs in s
    std::fill(c, c + static_cast<std::size_t>(m) * static_cast<std::size_t>(n), 0.0);
    k.gemm_nt_minus(m, n, ncol_d, ld + q0, nrow_d, ld + p1, nrow_d, c, m, sc.pack.data());
    for (int i = 0; i < m; ++i) rel[i] = map[rows_d[q0 + i]];
    for (int j = 0; j < n; ++j) {
      double* col = ls + static_cast<std::size_t>(map[rows_d[p1 + j]]) * nrow;
      const double* cj = c + static_cast<std::size_t>(j) * m;
      for (int i = std::max(0, p1 + j - q0); i < m; ++i) col[rel[i]] += cj[i];
    }
  }
}

double* SupernodalFactorize::pack() {
  return at(scratch_, thread_id()).pack.data();
}

bool SupernodalFactorize::fail_at(int s, int column) {
  if (column < 0) return false;
  bool expected = false;
  if (failed_.compare_exchange_strong(expected, true)) failed_column_ = columns_begin(s) + column;
  return true;
}

}  // namespace partita::fem::detail
