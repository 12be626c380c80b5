#pragma once
// How the particles are shared among the threads of a step: part t owns the particles
// [begin(t), begin(t + 1)), whole blocks of block_size, balanced by the work of the force pass.
// Pairs (i, j) of the neighbour list with j in a later part than i (cross pairs) are evaluated
// once each, before the parts' own rows, into cross_force; both owners add them in the same place
// of their sums, so every particle's force is a sum in a fixed order whatever the thread count.

#include "partita/dem/neighbor_list.hpp"

#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class ThreadPartition {
 public:
  static constexpr int block_size = 64;  ///< particles per block of the wall-force sums
  static constexpr int parallel_min_particles = 1024;  ///< fewer: one thread (a fork costs more)

  struct CrossPair {  ///< a listed pair (i, j) with j in a later part than i, in slot `slot`
    int i, j, slot;
  };
  struct CrossForce {  ///< its force on i and torques, evaluated before the parts' row loops
    Eigen::Vector3d force_i, torque_i, torque_j;
    double load = 0.0;  ///< contact load for the breakage criterion (when recorded)
    bool touching = false;
  };

  /// Splits n particles among up to `threads` parts (balanced by the lists when they are built);
  /// keeps the current split when it is still valid. Returns the number of parts.
  int update(int n, int threads, const NeighborList& lists);
  /// Lists the cross pairs of the current lists (after update()); cheap when still valid.
  void prepare_cross_pairs(const NeighborList& lists);
  /// The lists or the particle numbering changed: recompute at the next update().
  void invalidate() { valid_ = false; }

  int parts() const { return static_cast<int>(begin_.size()) - 1; }
  int begin(int part) const { return begin_[part]; }
  int part_of(int i) const;

  std::vector<CrossPair> cross_pairs;  ///< by part of i, then ascending i, j
  std::vector<int> cross_out_begin;    ///< parts + 1: cross pairs of part t's rows
  std::vector<int> cross_in;           ///< indices into cross_pairs, by part of j
  std::vector<int> cross_in_begin;     ///< parts + 1
  std::vector<CrossForce> cross_force;
  /// Per part, for a force pass that also runs the integrator's first half (System::step()):
  /// the particles [begin(t), drift_head_end[t]) and [drift_tail_begin[t], begin(t + 1)) take
  /// part in cross pairs and drift before the cross pairs are evaluated; the others drift as the
  /// part's rows reach them.
  std::vector<int> drift_head_end, drift_tail_begin;

 private:
  std::vector<int> begin_;
  std::vector<int> counts_;
  bool valid_ = false;
};

}  // namespace partita::dem
