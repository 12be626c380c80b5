#include "partita/fem/dof_partition.hpp"

namespace partita::fem {

DofPartition::DofPartition(const std::vector<char>& constrained)
    : free_index_(constrained.size(), -1) {
  for (std::size_t d = 0; d < constrained.size(); ++d) {
    if (constrained[d]) {
      constrained_.push_back(static_cast<Eigen::Index>(d));
    } else {
      free_index_[d] = static_cast<Eigen::Index>(free_.size());
      free_.push_back(static_cast<Eigen::Index>(d));
    }
  }
}

void DofPartition::split(const SparseMatrix& a, SparseMatrix& aff, SparseMatrix& afc) const {
  // Free dofs keep their relative order, so columns and rows stay sorted.
  const auto nf = static_cast<Eigen::Index>(free_.size());
  const auto nc = static_cast<Eigen::Index>(constrained_.size());
  auto extract = [&](const std::vector<Eigen::Index>& cols, Eigen::Index ncols, SparseMatrix& out) {
    std::vector<int> outer(static_cast<std::size_t>(ncols) + 1, 0), inner;
    std::vector<double> values;
    for (std::size_t k = 0; k < cols.size(); ++k) {
      for (SparseMatrix::InnerIterator it(a, cols[k]); it; ++it) {
        const Eigen::Index r = free_index_[static_cast<std::size_t>(it.row())];
        if (r >= 0) {
          inner.push_back(static_cast<int>(r));
          values.push_back(it.value());
        }
      }
      outer[k + 1] = static_cast<int>(inner.size());
    }
    out = Eigen::Map<SparseMatrix>(nf, ncols, static_cast<Eigen::Index>(inner.size()), outer.data(),
                                   inner.data(), values.data());
  };
  extract(free_, nf, aff);
  extract(constrained_, nc, afc);
}

void DofPartition::gather_free(const Eigen::VectorXd& full, Eigen::VectorXd& free) const {
  free.resize(num_free());
  for (std::size_t k = 0; k < free_.size(); ++k)
    free[static_cast<Eigen::Index>(k)] = full[free_[k]];
}

void DofPartition::scatter_free(const Eigen::VectorXd& free, Eigen::VectorXd& full) const {
  for (std::size_t k = 0; k < free_.size(); ++k)
    full[free_[k]] = free[static_cast<Eigen::Index>(k)];
}

}  // namespace partita::fem
