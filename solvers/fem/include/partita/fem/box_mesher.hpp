#pragma once
#include <array>

#include "partita/fem/element_type.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem {

// Structured mesh of the box [origin, origin + size] with cells[0] x cells[1] x cells[2] cells.
// Tetrahedra: each cell split into 6 (Kuhn split along its main diagonal; conforming).
// Result: one region "all"; node sets "all", "xmin", "xmax", "ymin", "ymax", "zmin", "zmax"
// (nodes on each boundary plane); faces of the same six names (outward surface elements:
// Quad4/Quad8 for hexahedra, Tri3/Tri6 for tetrahedra).
struct BoxSpec {
  Vec3 origin = Vec3::Zero();
  Vec3 size = Vec3::Ones();
  std::array<int, 3> cells = {1, 1, 1};
  ElementType element = ElementType::Hex8;
};

// Throws Error if a size is not positive or a cell count is < 1.
Mesh make_box_mesh(const BoxSpec& spec);

}  // namespace partita::fem
