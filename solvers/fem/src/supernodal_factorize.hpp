#pragma once
// A threaded numeric factorisation L L^T = P A P^T into CHOLMOD's supernodal storage, over
// CHOLMOD's symbolic analysis (the ordering, the supernodes and their row patterns).
//
// Why: CHOLMOD 3/4 (Debian 12) factorises its supernodes one after the other, on one core (the
// BLAS is OpenBLAS serial, for results independent of the thread count), and at 10^5 dofs and
// more the factorisation is the longest part of a plate's set-up, and of every Newton iteration.
//
// The method is CHOLMOD's own, left-looking by supernodes: supernode s is assembled from A, then
// every descendant d whose rows reach s's columns subtracts L_d(rows >= s) L_d(rows in s)^T
// (one product into a work block, scattered by a relative map), then s's diagonal block is
// factorised and the rows below it solved. The dense kernels are partita's own
// (supernodal_kernels.hpp: AVX2 + FMA or SSE2), not the BLAS: Debian's OpenBLAS (serial) gives
// wrong results now and then when two threads call dgemm or dtrsm at once (measured: 7 and 48 of
// 8,000 calls of random sizes on 2 threads differed from the same calls made one at a time). A
// supernode needs only finished descendants, so disjoint subtrees of the elimination tree run in
// parallel (OpenMP tasks, one per subtree above a work limit), and a large supernode near the root,
// which all threads wait for, shares its rows: its update and its triangular solve are cut into
// blocks of rows that the threads take as they come.
//
// Determinism: what a supernode computes (its list of descendants in ascending order, the blocks
// of rows, each kernel call's operands) is fixed by the factor's structure alone; threads decide
// only who runs which piece, never what the piece adds in which order. So the factor is the same
// bit for bit on any thread count and in every repeat (it differs from CHOLMOD's by round-off).
#include <atomic>
#include <cstdint>
#include <vector>

#include "supernodal_solve.hpp"

namespace partita::fem::detail {

// The pattern of A as compressed columns (a compressed Eigen SparseMatrix: column j holds the
// entries begin[j] .. begin[j+1], rows index[..]). Entries above the diagonal are ignored.
struct SparsePattern {
  int n = 0;
  const int *begin = nullptr, *index = nullptr;
};

class SupernodalFactorize {
 public:
  // Builds the schedule (the supernodal tree, each supernode's list of updating descendants, the
  // row blocks of the large supernodes) and where each entry of A lands in the factor. Returns
  // false when the structure does not have the properties relied on (supernodes postordered, rows
  // sorted, A's entries inside L's pattern): then use another factorisation.
  bool prepare(const SupernodalFactor& f, const SparsePattern& a);
  // Whether A's pattern is the one prepare() saw (the same columns and rows).
  bool same_pattern(const SparsePattern& a) const;
  // Factorises A (values ax, in the pattern's storage order) into values (the factor's storage,
  // f.px layout, overwritten). Uses the OpenMP threads available. Returns -1 on success, else a
  // column of P A P^T where a pivot was not positive (the matrix is not positive definite; the
  // values are then incomplete).
  int factorize(const SupernodalFactor& f, const double* ax, double* values);

 private:
  struct Update {
    int d;       // the descendant supernode
    int p1, p2;  // its rows [p1, p2) lie in this supernode's columns; [p1, nrow_d) in its rows
  };
  void subtree(const SupernodalFactor& f, double* values, int s, double task_min);
  void supernode(const SupernodalFactor& f, double* values, int s);
  void update_rows(const SupernodalFactor& f, double* values, int s, int r0, int r1);
  double* pack();  // this thread's pack buffer
  // records a failed pivot (column >= 0: a local column of s); returns whether it failed
  bool fail_at(int s, int column);
  int columns_begin(int s) const { return super_begin_[static_cast<std::size_t>(s)]; }

  int n_ = 0, nsuper_ = 0;
  std::vector<int> begin_, index_;  // A's pattern at prepare()
  std::vector<int> src_, dst_;      // A entry src_[k] goes to values[dst_[k]] (the factor's offsets
                                    // are CHOLMOD's int px: below 2^31)
  std::vector<std::int64_t> entry_begin_;    // supernode s's entries: entry_begin_[s] ..
  const double* ax_ = nullptr;               // A's values during factorize()
  std::vector<int> parent_, first_;          // supernodal tree; subtree of s: first_[s] .. s
  std::vector<int> child_begin_, children_;  // children of s: children_[child_begin_[s] ..]
  std::vector<double> subtree_work_;         // flops of s's subtree
  std::vector<int> update_begin_;            // updates of s: updates_[update_begin_[s] ..]
  std::vector<Update> updates_;
  std::vector<int> col_super_, super_begin_;
  std::vector<char> shared_;  // s's rows are cut into blocks of kRowBlock (structure's choice)
  double total_work_ = 0.0;
  std::size_t work_size_ = 0;  // largest update block (rows x columns)
  int widest_ = 0;             // most rows of a supernode
  // per thread: the relative map (row of P A P^T -> local row of map_owner), work block, rows
  struct Scratch {
    std::vector<int> map, rel;
    std::vector<double> c, pack;  // an update's block; packed operands (supernodal_kernels.hpp)
    int owner = -1;
  };
  std::vector<Scratch> scratch_;
  std::atomic<bool> failed_{false};
  int failed_column_ = -1;  // written by the first failure only
};

}  // namespace partita::fem::detail
