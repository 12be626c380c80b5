#pragma once
// Renumbering of the particles in cell order: a stable counting sort by cell (cells 2 R_max +
// skin wide over the bounding box, ordered by z, then y, then x). Spatial order keeps neighbours
// close in memory and each thread's range compact. Scratch is kept: no allocation once sized.

#include "partita/dem/particles.hpp"

#include <vector>

namespace partita::dem {

class CellOrder {
 public:
  /// Computes the order for the particles; false when it is the identity (nothing to do).
  bool compute(const Particles& particles, double skin);
  /// New index -> old index, and old -> new (valid after compute() returned true).
  const std::vector<int>& order() const { return order_; }
  const std::vector<int>& new_of_old() const { return new_of_old_; }

 private:
  std::vector<int> key_, order_, new_of_old_, start_;
};

}  // namespace partita::dem
