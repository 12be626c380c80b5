#pragma once
#include <array>
#include <span>

#include "partita/fem/element_type.hpp"
#include "partita/fem/face_type.hpp"

namespace partita::fem {

// Local faces of a volume element, each listed outward (counter-clockwise seen from outside),
// corners first then edge midpoints, as a face of type local_face_type().
int local_face_count(ElementType type);
FaceType local_face_type(ElementType type, int face);
std::span<const int> local_face_nodes(ElementType type, int face);
// Edges of a quadratic element: edge k joins the two corners and carries node corner_count + k.
// Empty for linear elements.
std::span<const std::array<int, 2>> quadratic_edges(ElementType type);

}  // namespace partita::fem
