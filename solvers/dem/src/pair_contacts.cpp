// PairContacts: the per-pair state following the neighbour list's slots, and its state format.
#include "partita/dem/pair_contacts.hpp"

#include "partita/dem/error.hpp"

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
  touching_.assign(n, 1);  // the next force pass settles forces and histories
}

void PairContacts::write(BinaryWriter& out) const {
  out.array(shear_);
  out.array(touching_);
}

void PairContacts::read(BinaryReader& in, std::size_t slots) {
  in.array(shear_, "pair histories");
  in.array(touching_, "pair contact flags");
  if (shear_.size() != slots || touching_.size() != slots)
    throw Error("corrupt state: neighbour list arrays do not agree");
}

}  // namespace partita::dem
