#pragma once
#include <span>
#include <vector>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// Sparsity pattern of a 3-dof-per-node matrix from the mesh's node adjacency (and, optionally,
// extra node groups coupled like an element's nodes: the FE operator's contributions beyond the
// material's declare them), and assembly of element matrices straight into the compressed
// storage (no triplets). Public because operator contributions add their tangents through it.
// Column 3 j + c holds, for each neighbour i of node j (sorted), rows 3 i, 3 i + 1, 3 i + 2.
class BlockAssembler {
 public:
  explicit BlockAssembler(const Mesh& mesh,
                          const std::vector<std::vector<std::size_t>>& extra_groups = {});
  // ndof x ndof matrix with the full pattern and zero values.
  SparseMatrix make_matrix() const;
  // A(3 a_g + r, 3 b_g + c) += Ke(3 a + r, 3 b + c) for the element's global nodes a_g, b_g.
  void add(SparseMatrix& a, std::span<const std::size_t> nodes, const ElementMatrix& ke) const;
  // The same, only into the columns of the nodes b_g in [first_node, end_node): threads that
  // take disjoint node ranges and the elements in the same order add every entry's
  // contributions in element order, as add() over all elements does.
  void add_columns(SparseMatrix& a, std::span<const std::size_t> nodes, const ElementMatrix& ke,
                   std::size_t first_node, std::size_t end_node) const;
  std::size_t num_nodes() const { return num_nodes_; }

 private:
  std::size_t num_nodes_ = 0;
  std::vector<std::size_t> offsets_;  // CSR over nodes
  std::vector<std::size_t> neighbours_;
};

}  // namespace partita::fem
