#pragma once
#include <array>

#include "partita/fem/element_type.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem {

// Structured mesh of the box [origin, origin + size] with cells[0] x cells[1] x cells[2] cells,
// or of a closed hollow box: the same outer box with walls of thickness wall_thickness (> 0)
// around an empty cavity [origin + t, origin + size - t].
// Hollow: cells[d] cells across the cavity along axis d, wall_cells cells through each wall, so
// cells[d] + 2 wall_cells along each outer edge; the cells of the cavity are left out (the mesh
// of the six walls, edges and corners shared, conforming).
// Tetrahedra: each cell split into 6 (Kuhn split along its main diagonal; conforming).
// Result: one region "all"; node sets "all", "xmin", "xmax", "ymin", "ymax", "zmin", "zmax"
// (nodes on each outer boundary plane); faces of the same six names (outward surface elements:
// Quad4/Quad8 for hexahedra, Tri3/Tri6 for tetrahedra). Hollow box also: face "inner" (the whole
// cavity surface, normals pointing into the cavity) with its node set "inner", and faces
// "inner_xmin" ... "inner_zmax" (the cavity's six sides, e.g. inner_xmin at x = origin.x + t).
struct BoxSpec {
  Vec3 origin = Vec3::Zero();
  Vec3 size = Vec3::Ones();
  std::array<int, 3> cells = {1, 1, 1};
  ElementType element = ElementType::Hex8;
  double wall_thickness = 0.0;  // 0: a solid box; > 0: hollow, < half the smallest edge
  int wall_cells = 1;           // hollow box: cells through the wall thickness
};

// Throws Error if a size is not positive, a cell count is < 1, or (hollow) the wall thickness is
// not in (0, min(size) / 2).
Mesh make_box_mesh(const BoxSpec& spec);

}  // namespace partita::fem
