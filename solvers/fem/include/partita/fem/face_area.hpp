#pragma once
#include <string>

#include "partita/fem/mesh.hpp"

namespace partita::fem {

// Area [m^2] of a named face in the reference configuration, A = sum_e sum_q w_q |dx/dxi x
// dx/deta| with each surface element's face rule (exact for flat faces). Throws Error for an
// unknown face (listing the known ones) or a degenerate surface element.
double face_area(const Mesh& mesh, const std::string& face);

// Area [m^2] of one face element's corner polygon (two triangles for a quadrilateral), in the
// reference configuration: the penalty contacts' share of a face per node.
double corner_area(const Mesh& mesh, const SurfaceElement& s);

// Volume [m^3] of a volume element in the reference configuration (its stiffness rule).
double element_volume(const Mesh& mesh, const Element& e);

}  // namespace partita::fem
