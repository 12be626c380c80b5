#include "partita/fem/block_assembler.hpp"

#include <algorithm>

namespace partita::fem {

BlockAssembler::BlockAssembler(const Mesh& mesh,
                               const std::vector<std::vector<std::size_t>>& extra_groups)
    : num_nodes_(mesh.num_nodes()) {
  std::vector<std::vector<std::size_t>> adj(num_nodes_);
  for (const auto& e : mesh.elements()) {
    const auto nodes = e.node_span();
    for (auto i : nodes) adj[i].insert(adj[i].end(), nodes.begin(), nodes.end());
  }
  for (const auto& nodes : extra_groups) {
    for (auto i : nodes) adj.at(i).insert(adj[i].end(), nodes.begin(), nodes.end());
  }
  offsets_.assign(num_nodes_ + 1, 0);
  for (std::size_t i = 0; i < num_nodes_; ++i) {
    auto& a = adj[i];
    a.push_back(i);
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    offsets_[i + 1] = offsets_[i] + a.size();
  }
  neighbours_.reserve(offsets_.back());
  for (auto& a : adj) neighbours_.insert(neighbours_.end(), a.begin(), a.end());
}

SparseMatrix BlockAssembler::make_matrix() const {
  const auto ndof = static_cast<Eigen::Index>(3 * num_nodes_);
  std::vector<int> outer(static_cast<std::size_t>(ndof) + 1);
  std::vector<int> inner;
  inner.reserve(9 * neighbours_.size());
  outer[0] = 0;
  for (std::size_t j = 0; j < num_nodes_; ++j) {
    for (int c = 0; c < 3; ++c) {
      for (std::size_t k = offsets_[j]; k < offsets_[j + 1]; ++k) {
        for (int r = 0; r < 3; ++r) inner.push_back(static_cast<int>(3 * neighbours_[k]) + r);
      }
      outer[3 * j + static_cast<std::size_t>(c) + 1] = static_cast<int>(inner.size());
    }
  }
  std::vector<double> values(inner.size(), 0.0);
  return Eigen::Map<SparseMatrix>(ndof, ndof, static_cast<Eigen::Index>(inner.size()), outer.data(),
                                  inner.data(), values.data());
}

void BlockAssembler::add(SparseMatrix& a, std::span<const std::size_t> nodes,
                         const ElementMatrix& ke) const {
  add_columns(a, nodes, ke, 0, num_nodes_);
}

void BlockAssembler::add_columns(SparseMatrix& a, std::span<const std::size_t> nodes,
                                 const ElementMatrix& ke, std::size_t first_node,
                                 std::size_t end_node) const {
  double* values = a.valuePtr();
  const int* outer = a.outerIndexPtr();
  const auto n = nodes.size();
  for (std::size_t b = 0; b < n; ++b) {
    const std::size_t j = nodes[b];
    if (j < first_node || j >= end_node) continue;
    const auto first = neighbours_.begin() + static_cast<std::ptrdiff_t>(offsets_[j]);
    const auto last = neighbours_.begin() + static_cast<std::ptrdiff_t>(offsets_[j + 1]);
    for (std::size_t aa = 0; aa < n; ++aa) {
      const auto k = static_cast<std::size_t>(std::lower_bound(first, last, nodes[aa]) - first);
      for (int c = 0; c < 3; ++c) {
        double* col = values + outer[3 * j + static_cast<std::size_t>(c)] + 3 * k;
        for (int r = 0; r < 3; ++r) {
          col[r] += ke(static_cast<Eigen::Index>(3 * aa) + r, static_cast<Eigen::Index>(3 * b) + c);
        }
      }
    }
  }
}

}  // namespace partita::fem
