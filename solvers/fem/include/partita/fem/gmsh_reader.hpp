#pragma once
#include <istream>
#include <string>

#include "partita/fem/mesh.hpp"

namespace partita::fem {

// Reads a Gmsh 4.1 ASCII mesh file (.msh).
//   3D elements: Tet4 (gmsh type 4), Hex8 (5), Tet10 (11), Hex20 (17; incomplete serendipity,
//     Mesh.SecondOrderIncomplete = 1). Nodes are reordered to partita's (VTK) ordering.
//   Volume physical groups -> element regions (an element's region is the first physical group
//     of its entity; elements of entities without one go to region "default"), and node sets.
//   Surface physical groups (Tri3 2, Quad4 3, Tri6 9, Quad8 16) -> named faces, re-oriented
//     outward from the volume element they bound, and node sets of their nodes.
//   Points and lines are ignored; nodes used by no volume element are dropped.
// Throws Error("file:line: what was wrong; what is allowed") on malformed input: every count and
// tag is checked (sign, range, and counts against the bytes left in the file), and meshes larger
// than the solver's 32-bit numbering (715827882 nodes, 2147483647 elements) are refused.
Mesh read_gmsh(const std::string& path);
// The same from a stream (seekable streams get the counts-against-bytes check); `source` names
// the content in messages.
Mesh read_gmsh(std::istream& in, const std::string& source);

}  // namespace partita::fem
