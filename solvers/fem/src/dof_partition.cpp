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

namespace {
// Refills the values of `out` from the columns `cols` of `a` when out already has the pattern
// that extracting them would give (a matrix of the same pattern split before): no allocation.
// False (out untouched in its pattern, values possibly partly written) when the patterns differ.
bool refill(const SparseMatrix& a, const std::vector<Eigen::Index>& cols,
            const std::vector<Eigen::Index>& free_index, Eigen::Index nf, SparseMatrix& out) {
  if (!out.isCompressed() || out.rows() != nf ||
      out.cols() != static_cast<Eigen::Index>(cols.size()))
    return false;
  const int* outer = out.outerIndexPtr();
  const int* inner = out.innerIndexPtr();
  double* values = out.valuePtr();
  int pos = 0;
  for (std::size_t k = 0; k < cols.size(); ++k) {
    if (outer[k] != pos) return false;
    for (SparseMatrix::InnerIterator it(a, cols[k]); it; ++it) {
      const Eigen::Index r = free_index[static_cast<std::size_t>(it.row())];
      if (r < 0) continue;
      if (pos >= out.nonZeros() || inner[pos] != r) return false;
      values[pos++] = it.value();
    }
  }
  return pos == out.nonZeros();
}
}  // namespace

void DofPartition::split(const SparseMatrix& a, SparseMatrix& aff, SparseMatrix& afc) const {
  // Free dofs keep their relative order, so columns and rows stay sorted.
  const auto nf = static_cast<Eigen::Index>(free_.size());
  const auto nc = static_cast<Eigen::Index>(constrained_.size());
  // the same pattern as at the last split (a Newton tangent, iteration after iteration): values
  // only
  if (aff.nonZeros() > 0 && refill(a, free_, free_index_, nf, aff) &&
      refill(a, constrained_, free_index_, nf, afc))
    return;
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
