#pragma once
#include <string>
#include <string_view>

namespace partita::fem {

// Volume element types. Node ordering follows VTK (corners first, then edge midpoints):
//   Hex8/Hex20: corners 0-3 bottom (zeta=-1) counter-clockwise, 4-7 top; Hex20 edge nodes
//     8:(0,1) 9:(1,2) 10:(2,3) 11:(3,0) 12:(4,5) 13:(5,6) 14:(6,7) 15:(7,4)
//     16:(0,4) 17:(1,5) 18:(2,6) 19:(3,7).
//   Tet4/Tet10: corners 0-3 with positive volume; Tet10 edge nodes
//     4:(0,1) 5:(1,2) 6:(2,0) 7:(0,3) 8:(1,3) 9:(2,3).
enum class ElementType { Hex8, Hex20, Tet4, Tet10 };

int node_count(ElementType type);
int corner_count(ElementType type);
std::string_view to_string(ElementType type);
// "hex8", "hex20", "tet4", "tet10" (case-insensitive); throws Error listing those otherwise.
ElementType element_type_from_string(std::string_view name);

}  // namespace partita::fem
