#pragma once
#include <string_view>

namespace partita::fem {

// Surface element types; corners counter-clockwise seen from outside (outward normal
// dx/dxi x dx/deta), then edge midpoints (c0,c1), (c1,c2), ...
enum class FaceType { Quad4, Quad8, Tri3, Tri6 };

int node_count(FaceType type);
int corner_count(FaceType type);
std::string_view to_string(FaceType type);

}  // namespace partita::fem
