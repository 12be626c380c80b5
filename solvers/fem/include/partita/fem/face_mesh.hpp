#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "partita/fem/face_type.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// A named face as a stand-alone surface mesh (for a coupling interface), reference config.
struct FaceMesh {
  struct Cell {
    FaceType type;
    std::array<int, 8> nodes;  // indices into FaceMesh::nodes (first node_count(type) used)
  };
  std::vector<std::size_t> nodes;  // global node indices, sorted
  MatrixX3 positions;              // reference positions of those nodes
  std::vector<Cell> cells;         // the face's surface elements, outward
  // Linear triangles over all face nodes (Quad4 -> 2, Quad8 -> 6, Tri3 -> 1, Tri6 -> 4),
  // outward, as indices into nodes.
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangle_cells;         // the cell each triangle lies on
  std::vector<std::size_t> cell_elements;  // the volume element each cell bounds (global id)
  // the element on each cell's other side (Mesh::face_across(): num_elements() on the boundary)
  std::vector<std::size_t> cell_across;
};

}  // namespace partita::fem
