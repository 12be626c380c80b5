#pragma once
// Internal to solvers/fem: the conforming mesh of a tensor-product grid of cells with a solid
// mask, the common part of the box mesher (box_mesher.cpp) and the panel mesher
// (panel_mesher.cpp).
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "partita/fem/element_type.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem::detail {

using GridCell = std::array<long, 3>;  // cell indices along x, y, z

struct MaskedGrid {
  // Cell boundaries along x, y, z, strictly increasing: cells[d] + 1 lines along axis d.
  std::array<std::vector<double>, 3> lines;
  // Element regions, region index 0 first (Mesh::add_region order).
  std::vector<std::string> regions;
  // Region index (into `regions`) of a cell, or -1 for an empty cell (no elements).
  std::function<int(const GridCell&)> region;
  // The face sets that a boundary face of the solid cell `cell` joins: its face on the lower
  // (upper = 0) or upper (upper = 1) side along axis d, whose neighbour across is an empty cell
  // or (outside = true) beyond the grid. Appends the names to `names` (none: the face is in no
  // set).
  std::function<void(const GridCell& cell, int d, int upper, bool outside,
                     std::vector<std::string>& names)>
      faces;
};

// One hexahedron (Hex8, Hex20) per solid cell, or six tetrahedra (Tet4, Tet10: the Kuhn split
// along the cell's main diagonal), cells visited z-, then y-, then x-outermost (x fastest). The
// nodes lie on a lattice twice as fine as the cells (cell corners, edge and face midpoints) and
// are shared by every element that uses them: the mesh is conforming where solid cells touch.
// Boundary faces are outward surface elements of the element they bound (Quad4/Quad8 or
// Tri3/Tri6) in the sets `faces` names; node sets: "all" and one per face set (its nodes).
Mesh make_masked_grid_mesh(const MaskedGrid& grid, ElementType type);

}  // namespace partita::fem::detail
