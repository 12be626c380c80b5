#include "partita/dem/thread_partition.hpp"

#include <algorithm>

namespace partita::dem {

int ThreadPartition::update(int n, int threads, const NeighborList& nl) {
  const int blocks = (n + block_size - 1) / block_size;
  const int parts = n >= parallel_min_particles ? std::max(1, std::min(threads, blocks)) : 1;
  if (valid_ && static_cast<int>(begin_.size()) == parts + 1 && begin_.back() == n) return parts;
  // Whole blocks per part, balancing the work of the force pass: per particle a fixed cost worth
  // about two listed pairs, plus its listed pairs (known since the last build).
  const bool have_lists = static_cast<int>(nl.offsets_.size()) == n + 1;
  auto block_cost = [&](int b) {
    const int lo = b * block_size, hi = std::min(n, lo + block_size);
    return 2.0 * (hi - lo) + (have_lists ? nl.offsets_[hi] - nl.offsets_[lo] : 0);
  };
  double total = 0.0;
  for (int b = 0; b < blocks; ++b) total += block_cost(b);
  begin_.assign(parts + 1, n);
  begin_[0] = 0;
  double sum = 0.0;
  int t = 1;
  for (int b = 0; b + 1 < blocks && t < parts; ++b) {
    sum += block_cost(b);
    // part t starts after block b once the parts before it have their share, or when every
    // later part needs one of the blocks left
    if (sum >= total * t / parts || blocks - (b + 1) == parts - t)
      begin_[t++] = (b + 1) * block_size;
  }
  valid_ = false;
  return parts;
}

int ThreadPartition::part_of(int i) const {
  return static_cast<int>(std::upper_bound(begin_.begin(), begin_.end(), i) - begin_.begin()) - 1;
}

void ThreadPartition::prepare_cross_pairs(const NeighborList& nl) {
  if (valid_) return;
  const int np = parts();
  cross_pairs.clear();
  cross_out_begin.assign(np + 1, 0);
  for (int t = 0; t < np; ++t) {
    const int hi = begin_[t + 1];
    for (int i = begin_[t]; i < hi; ++i) {
      // rows are sorted: the pairs with j beyond the part come last
      int s = nl.offsets_[i + 1];
      while (s > nl.offsets_[i] && nl.neighbors_[s - 1] >= hi) --s;
      for (; s < nl.offsets_[i + 1]; ++s) cross_pairs.push_back({i, nl.neighbors_[s], s});
    }
    cross_out_begin[t + 1] = static_cast<int>(cross_pairs.size());
  }
  cross_force.resize(cross_pairs.size());
  // incoming: for each part, the cross pairs whose j it owns, in the order of cross_pairs
  // (ascending i, then j)
  cross_in_begin.assign(np + 1, 0);
  for (const CrossPair& c : cross_pairs) ++cross_in_begin[part_of(c.j) + 1];
  for (int t = 0; t < np; ++t) cross_in_begin[t + 1] += cross_in_begin[t];
  cross_in.resize(cross_pairs.size());
  counts_.assign(np, 0);
  for (int k = 0; k < static_cast<int>(cross_pairs.size()); ++k) {
    const int t = part_of(cross_pairs[k].j);
    cross_in[cross_in_begin[t] + counts_[t]++] = k;
  }
  // the particles of each part that cross pairs read: a head (incoming j) and a tail (outgoing i)
  drift_head_end.resize(np);
  drift_tail_begin.resize(np);
  for (int t = 0; t < np; ++t) {
    int head = begin_[t], tail = begin_[t + 1];
    for (int k = cross_in_begin[t]; k < cross_in_begin[t + 1]; ++k)
      head = std::max(head, cross_pairs[cross_in[k]].j + 1);
    for (int k = cross_out_begin[t]; k < cross_out_begin[t + 1]; ++k)
      tail = std::min(tail, cross_pairs[k].i);
    drift_head_end[t] = head;
    drift_tail_begin[t] = std::max(head, tail);
  }
  valid_ = true;
}

}  // namespace partita::dem
