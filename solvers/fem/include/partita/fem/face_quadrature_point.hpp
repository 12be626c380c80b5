#pragma once
#include <cstddef>

#include "partita/fem/types.hpp"

namespace partita::fem {

// A quadrature point of a named face in the reference configuration.
struct FaceQuadraturePoint {
  Vec3 position;                 // x [m]
  Vec3 normal;                   // outward unit normal
  double weight = 0.0;           // w |dx/dxi x dx/deta| [m^2]: the area this point integrates
  std::size_t face_element = 0;  // index of its surface element in Mesh::face(name)
};

}  // namespace partita::fem
