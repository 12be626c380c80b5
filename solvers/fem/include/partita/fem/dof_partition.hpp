#pragma once
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem {

// Split of the dofs into free (f) and constrained (c) ones, both in increasing order, and the
// matrix / vector extractions that go with it.
class DofPartition {
 public:
  DofPartition() = default;
  // constrained[d] != 0 marks dof d as constrained.
  explicit DofPartition(const std::vector<char>& constrained);

  const std::vector<Eigen::Index>& free_dofs() const { return free_; }
  const std::vector<Eigen::Index>& constrained_dofs() const { return constrained_; }
  Eigen::Index num_free() const { return static_cast<Eigen::Index>(free_.size()); }

  // A_ff and A_fc of a full matrix (columns and rows keep their order).
  void split(const SparseMatrix& a, SparseMatrix& aff, SparseMatrix& afc) const;
  // x_f = x[free];  x[free] = x_f.
  void gather_free(const Eigen::VectorXd& full, Eigen::VectorXd& free) const;
  void scatter_free(const Eigen::VectorXd& free, Eigen::VectorXd& full) const;

 private:
  std::vector<Eigen::Index> free_index_;  // -1 for constrained dofs
  std::vector<Eigen::Index> free_, constrained_;
};

}  // namespace partita::fem
