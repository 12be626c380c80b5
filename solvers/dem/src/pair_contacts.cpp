// PairContacts: the per-pair state following the neighbour list's slots, and its state format.
#include "partita/dem/pair_contacts.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace partita::dem {

void PairContacts::follow(const std::vector<NeighborList::SlotSource>& sources) {
  const std::size_t n = sources.size();
  new_shear_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const NeighborList::SlotSource src = sources[k];
    if (src.slot < 0)
      new_shear_[k].setZero();
    else if (src.flipped)
      new_shear_[k] = -shear_[src.slot];
    else
      new_shear_[k] = shear_[src.slot];
  }
  shear_.swap(new_shear_);
  if (keep_plastic_) {
    new_plastic_.resize(n);
    for (std::size_t k = 0; k < n; ++k)
      new_plastic_[k] = sources[k].slot < 0 || plastic_.empty() ? 0.0f : plastic_[sources[k].slot];
    plastic_.swap(new_plastic_);
  }
  touching_.assign(n, 1);  // the next force pass settles forces and histories
}

void PairContacts::keep_plastic() {
  keep_plastic_ = true;
  plastic_.assign(shear_.size(), 0.0f);
}

void PairContacts::write(BinaryWriter& out) const {
  out.array(shear_);
  out.array(touching_);
  out.array(plastic_);
}

void PairContacts::read(BinaryReader& in, std::size_t slots, bool with_plastic) {
  in.array(shear_, "pair histories");
  in.array(touching_, "pair contact flags");
  if (with_plastic)
    in.array(plastic_, "pair permanent overlaps");
  else
    plastic_.clear();
  if (shear_.size() != slots || touching_.size() != slots ||
      !(plastic_.empty() || plastic_.size() == slots))
    throw Error("corrupt state: neighbour list arrays do not agree");
  // a state of a system without yielding particles, read by one with them: none yet (and the
  // other way round: the permanent overlaps are dropped, as the contacts are then elastic)
  if (keep_plastic_ && plastic_.empty())
    plastic_.assign(slots, 0.0f);
  else if (!keep_plastic_)
    plastic_.clear();
}

// ---- histories that travel with their particles ---------------------------------------------

namespace {

void put_record(const PairContacts::Record& r, std::byte* at) {
  std::memcpy(at, &r.id_i, 8);
  std::memcpy(at + 8, &r.id_j, 8);
  std::memcpy(at + 16, r.shear.data(), 24);
  std::memcpy(at + 40, &r.touching, 1);
  std::memcpy(at + 41, &r.plastic, 4);
}

PairContacts::Record get_record(const std::byte* at) {
  PairContacts::Record r;
  std::memcpy(&r.id_i, at, 8);
  std::memcpy(&r.id_j, at + 8, 8);
  std::memcpy(r.shear.data(), at + 16, 24);
  std::memcpy(&r.touching, at + 40, 1);
  std::memcpy(&r.plastic, at + 41, 4);
  return r;
}

}  // namespace

std::size_t PairContacts::pack(const NeighborList& nl, const std::vector<std::int64_t>& id,
                               const std::vector<char>& chosen,
                               const std::vector<std::int64_t>& chosen_ids,
                               std::vector<std::byte>& out) const {
  // the rows of the last build (particles added since have none); the slots this object holds
  const int rows = static_cast<int>(nl.offsets_.size()) - 1;
  std::size_t count = 0;
  const auto append = [&](const Record& r) {
    const std::size_t at = out.size();
    out.resize(at + record_bytes);
    put_record(r, out.data() + at);
    ++count;
  };
  if (shear_.size() == nl.neighbors_.size()) {
    for (int i = 0; i < rows; ++i) {
      for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
        const int j = nl.neighbors_[s];
        const float plastic = plastic_.empty() ? 0.0f : plastic_[s];
        if (!(chosen[i] || chosen[j]) || (shear_[s] == Eigen::Vector3d::Zero() && plastic == 0.0f))
          continue;
        append(Record{id[i], id[j], shear_[s], touching_[s], plastic});
      }
    }
  }
  for (const Record& r : waiting_)
    if (std::binary_search(chosen_ids.begin(), chosen_ids.end(), r.id_i) ||
        std::binary_search(chosen_ids.begin(), chosen_ids.end(), r.id_j))
      append(r);
  return count;
}

void PairContacts::check_packed(const std::byte* data, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) {
    const Record r = get_record(data + k * record_bytes);
    const bool plastic_ok = std::isfinite(r.plastic) && r.plastic >= 0.0f;
    if (r.id_i < 0 || r.id_j < 0 || r.id_i == r.id_j || !r.shear.allFinite() || !plastic_ok)
      throw Error("pair history " + std::to_string(k) + " of the message names particles " +
                  std::to_string(r.id_i) + " and " + std::to_string(r.id_j) +
                  (r.shear.allFinite() ? "" : " with a spring that is not finite") +
                  (plastic_ok ? "" : " with a permanent overlap that is not a finite value >= 0") +
                  " (a pair needs two distinct ids >= 0: corrupt or foreign bytes?)");
  }
}

void PairContacts::add_waiting(const std::byte* data, std::size_t count) {
  const std::size_t first = waiting_.size();
  waiting_.resize(first + count);
  for (std::size_t k = 0; k < count; ++k) waiting_[first + k] = get_record(data + k * record_bytes);
}

void PairContacts::place_waiting(const NeighborList& nl, const std::vector<std::int64_t>& id) {
  if (waiting_.empty()) return;
  const int n = static_cast<int>(id.size());
  index_of_id_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) index_of_id_[i] = {id[i], i};
  std::sort(index_of_id_.begin(), index_of_id_.end());
  const auto index = [&](std::int64_t want) {
    const auto it = std::lower_bound(index_of_id_.begin(), index_of_id_.end(),
                                     std::pair<std::int64_t, int>{want, -1});
    return it != index_of_id_.end() && it->first == want ? it->second : -1;
  };
  const std::vector<NeighborList::SlotSource>& sources = nl.slot_sources();
  const int rows = static_cast<int>(nl.offsets_.size()) - 1;
  for (const Record& r : waiting_) {
    const int a = index(r.id_i), b = index(r.id_j);
    if (a < 0 || b < 0) continue;  // a particle that is not here
    const int row = std::min(a, b), j = std::max(a, b);
    if (row >= rows) continue;
    const int* begin = nl.neighbors_.data() + nl.offsets_[row];
    const int* end = nl.neighbors_.data() + nl.offsets_[row + 1];
    const int* at = std::lower_bound(begin, end, j);
    if (at == end || *at != j) continue;  // not listed: beyond the cut-off
    const auto s = static_cast<std::size_t>(at - nl.neighbors_.data());
    if (s < sources.size() && sources[s].slot >= 0) continue;  // carried over by the build
    // (the slot keeps follow()'s touching mark: the next force pass settles the pair)
    shear_[s] = a < b ? r.shear : Eigen::Vector3d(-r.shear);
    if (!plastic_.empty()) plastic_[s] = r.plastic;
  }
  waiting_.clear();
}

}  // namespace partita::dem
