// NeighborList::insert_offspring(): particles born inside others (fragments) taken into the
// lists without a search, and listed_neighbours().
#include "partita/dem/error.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/parallel.hpp"

#include <algorithm>
#include <string>

namespace partita::dem {

void NeighborList::insert_offspring(const std::vector<int>& new_of_old, int kept,
                                    const std::vector<Offspring>& born, const Particles& p) {
  const int old_n = static_cast<int>(offsets_.size()) - 1;
  const int nb = static_cast<int>(born.size());
  const int n = kept + nb;
  if (!built() || static_cast<int>(position_at_build_.size()) != old_n ||
      static_cast<int>(new_of_old.size()) != old_n || static_cast<int>(p.size()) != n ||
      static_cast<int>(plane_mask_.size()) != old_n) {
    throw Error("insert_offspring: the lists were not built for the " +
                std::to_string(new_of_old.size()) +
                " particles before the change; rebuild them instead");
  }
  const bool meshes = old_n > 0 && mesh_offsets_.size() == static_cast<std::size_t>(old_n) + 1;
  // The parents (each a particle gone with the change) and their newborns, in order of first
  // appearance: born_offsets_/born_items_ hold the newborns of parent P.
  parent_of_.assign(old_n, -1);
  int parents = 0;
  for (int k = 0; k < nb; ++k) {
    const int q = born[k].parent;
    if (q < 0 || q >= old_n || new_of_old[q] >= 0)
      throw Error("insert_offspring: newborn " + std::to_string(k) + " names parent " +
                  std::to_string(q) + ", which is not a particle gone with the change");
    if (parent_of_[q] < 0) parent_of_[q] = parents++;
  }
  born_offsets_.assign(parents + 1, 0);
  for (int k = 0; k < nb; ++k) ++born_offsets_[parent_of_[born[k].parent] + 1];
  for (int q = 0; q < parents; ++q) born_offsets_[q + 1] += born_offsets_[q];
  born_items_.resize(nb);
  counts_.assign(parents, 0);
  for (int k = 0; k < nb; ++k) {
    const int q = parent_of_[born[k].parent];
    born_items_[born_offsets_[q] + counts_[q]++] = k;
  }
  // Every listed neighbour of each parent (both halves), in the parents' order.
  parent_list_.resize(parents);
  for (int q = 0; q < old_n; ++q)
    if (parent_of_[q] >= 0) parent_list_[parent_of_[q]] = static_cast<std::size_t>(q);
  listed_neighbours(parent_list_, parent_nb_offsets_, parent_nb_);
  // The newborns' references: the parent's position at the build plus the offset (so that the
  // displacement since the build is the parent's), and the parent's planes.
  born_reference_.resize(nb);
  born_mask_.resize(nb);
  for (int k = 0; k < nb; ++k) {
    born_reference_[k] = position_at_build_[born[k].parent] + born[k].offset;
    born_mask_[k] = plane_mask_[born[k].parent];
  }
  // The newborns' pairs (a, b), a < b, by the build's cut-off at the references.
  added_pairs_.clear();
  auto near = [&](const Eigen::Vector3d& xa, double ra, const Eigen::Vector3d& xb, double rb) {
    const double cut = ra + skin_ + rb;
    return (xb - xa).squaredNorm() < cut * cut;
  };
  for (int k = 0; k < nb; ++k) {
    const int a = kept + k, q = parent_of_[born[k].parent];
    const Eigen::Vector3d& xa = born_reference_[k];
    const double ra = p.radius[a];
    for (int s = parent_nb_offsets_[q]; s < parent_nb_offsets_[q + 1]; ++s) {
      const int j = parent_nb_[s];
      if (new_of_old[j] >= 0) {
        const int jn = new_of_old[j];
        if (near(xa, ra, position_at_build_[j], p.radius[jn])) added_pairs_.emplace_back(jn, a);
      } else if (parent_of_[j] >= 0) {  // a neighbouring parent: its newborns after this one
        const int pj = parent_of_[j];
        for (int t = born_offsets_[pj]; t < born_offsets_[pj + 1]; ++t) {
          const int g = born_items_[t], b = kept + g;
          if (b > a && near(xa, ra, born_reference_[g], p.radius[b])) added_pairs_.emplace_back(a, b);
        }
      }
    }
    for (int t = born_offsets_[q]; t < born_offsets_[q + 1]; ++t) {  // its siblings
      const int g = born_items_[t], b = kept + g;
      if (b > a && near(xa, ra, born_reference_[g], p.radius[b])) added_pairs_.emplace_back(a, b);
    }
  }
  std::sort(added_pairs_.begin(), added_pairs_.end());
  // New rows: the kept pairs in their order (the numbering is kept ascending), then the added
  // pairs (their second index is a newborn's, above every kept particle's).
  new_offsets_.assign(n + 1, 0);
  for (int i = 0; i < old_n; ++i) {
    if (new_of_old[i] < 0) continue;
    int c = 0;
    for (int s = offsets_[i]; s < offsets_[i + 1]; ++s) c += new_of_old[neighbors_[s]] >= 0;
    new_offsets_[new_of_old[i] + 1] = c;
  }
  for (const auto& [a, b] : added_pairs_) ++new_offsets_[a + 1];
  for (int i = 0; i < n; ++i) new_offsets_[i + 1] += new_offsets_[i];
  new_neighbors_.resize(new_offsets_[n]);
  slot_source_.resize(new_offsets_[n]);
  counts_.assign(n, 0);
  for (int i = 0; i < old_n; ++i) {
    const int a = new_of_old[i];
    if (a < 0) continue;
    for (int s = offsets_[i]; s < offsets_[i + 1]; ++s) {
      const int b = new_of_old[neighbors_[s]];
      if (b < 0) continue;
      const int slot = new_offsets_[a] + counts_[a]++;
      new_neighbors_[slot] = b;
      slot_source_[slot] = {s, false};
    }
  }
  for (const auto& [a, b] : added_pairs_) {
    const int slot = new_offsets_[a] + counts_[a]++;
    new_neighbors_[slot] = b;
    slot_source_[slot] = {-1, false};
  }
  offsets_.swap(new_offsets_);
  neighbors_.swap(new_neighbors_);
  // Build references and planes: the kept particles' moved down, the newborns' appended.
  for (int i = 0; i < old_n; ++i) {
    const int a = new_of_old[i];
    if (a < 0) continue;
    position_at_build_[a] = position_at_build_[i];
    plane_mask_[a] = plane_mask_[i];
  }
  position_at_build_.resize(kept);
  plane_mask_.resize(kept);
  position_at_build_.insert(position_at_build_.end(), born_reference_.begin(), born_reference_.end());
  plane_mask_.insert(plane_mask_.end(), born_mask_.begin(), born_mask_.end());
  // Mesh candidates: the kept particles' rows, then each newborn with its parent's.
  if (meshes) {
    new_mesh_offsets_.assign(n + 1, 0);
    new_mesh_candidates_.clear();
    auto copy_row = [&](int row, int to) {
      new_mesh_candidates_.insert(new_mesh_candidates_.end(),
                                  mesh_candidates_.begin() + mesh_offsets_[row],
                                  mesh_candidates_.begin() + mesh_offsets_[row + 1]);
      new_mesh_offsets_[to + 1] = static_cast<int>(new_mesh_candidates_.size());
    };
    for (int i = 0; i < old_n; ++i)
      if (new_of_old[i] >= 0) copy_row(i, new_of_old[i]);
    for (int k = 0; k < nb; ++k) copy_row(born[k].parent, kept + k);
    mesh_offsets_.swap(new_mesh_offsets_);
    mesh_candidates_.swap(new_mesh_candidates_);
  }
}

namespace {

// The slots s of rows [0, rows) whose pair (i, neighbors[s]) has a member (member(i) or
// member(j)), as (i, s) in the list's order. The rows are cut into blocks, scanned on the threads
// (each block into its own scratch), and the blocks' hits joined in block order: the same list
// whatever the number of threads.
template <class Member>
void scan_touching(const std::vector<int>& offsets, const std::vector<int>& neighbors, Member member,
                   std::vector<std::vector<std::pair<int, int>>>& blocks,
                   std::vector<std::pair<int, int>>& out) {
  out.clear();
  const int rows = static_cast<int>(offsets.size()) - 1;
  if (rows <= 0) return;
  const int nb = rows >= parallel_pass_min ? std::max(1, max_threads()) : 1;
  if (static_cast<int>(blocks.size()) < nb) blocks.resize(nb);
  auto scan = [&](int b) {
    std::vector<std::pair<int, int>>& hits = blocks[b];
    hits.clear();
    const int first = static_cast<int>(static_cast<long long>(rows) * b / nb);
    const int last = static_cast<int>(static_cast<long long>(rows) * (b + 1) / nb);
    for (int i = first; i < last; ++i) {
      const bool in_i = member(i);
      for (int s = offsets[i]; s < offsets[i + 1]; ++s)
        if (in_i || member(neighbors[s])) hits.emplace_back(i, s);
    }
  };
  if (nb == 1) {
    scan(0);
  } else {
#pragma omp parallel for schedule(static, 1)
    for (int b = 0; b < nb; ++b) scan(b);
  }
  for (int b = 0; b < nb; ++b) out.insert(out.end(), blocks[b].begin(), blocks[b].end());
}

}  // namespace

void NeighborList::slots_touching(const std::vector<char>& in,
                                  std::vector<std::pair<int, int>>& out) const {
  const std::size_t rows = offsets_.empty() ? 0 : offsets_.size() - 1;
  if (in.size() < rows)
    throw Error("slots_touching: need one flag per listed particle (" + std::to_string(rows) +
                "), got " + std::to_string(in.size()));
  scan_touching(offsets_, neighbors_, [&](int i) { return in[i] != 0; }, touching_blocks_, out);
}

void NeighborList::listed_neighbours(const std::vector<std::size_t>& which,
                                     std::vector<int>& offsets, std::vector<int>& items) const {
  const int rows = static_cast<int>(offsets_.size()) - 1;
  const int m = static_cast<int>(which.size());
  std::vector<int>& slot_of = mark_;  // (scratch)
  slot_of.assign(std::max(rows, 0), -1);
  for (int k = 0; k < m; ++k) {
    const auto i = which[k];
    if (i >= static_cast<std::size_t>(rows) || slot_of[i] >= 0)
      throw Error("listed_neighbours: bad or repeated particle index " + std::to_string(i));
    slot_of[i] = k;
  }
  scan_touching(offsets_, neighbors_, [&](int i) { return slot_of[i] >= 0; }, touching_blocks_,
                touching_);
  // the hits in row order: each particle's neighbours come out ascending (those before it from
  // their rows, then its own row)
  offsets.assign(m + 1, 0);
  for (const auto& [i, s] : touching_) {
    const int ki = slot_of[i], kj = slot_of[neighbors_[s]];
    if (ki >= 0) ++offsets[ki + 1];
    if (kj >= 0) ++offsets[kj + 1];
  }
  for (int k = 0; k < m; ++k) offsets[k + 1] += offsets[k];
  items.resize(offsets[m]);
  mark_counts_.assign(m, 0);
  for (const auto& [i, s] : touching_) {
    const int j = neighbors_[s], ki = slot_of[i], kj = slot_of[j];
    if (ki >= 0) items[offsets[ki] + mark_counts_[ki]++] = j;
    if (kj >= 0) items[offsets[kj] + mark_counts_[kj]++] = i;
  }
}

}  // namespace partita::dem
