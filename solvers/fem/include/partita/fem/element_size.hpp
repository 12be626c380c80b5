#pragma once
// The characteristic length of a volume element at a given shape: its volume over its largest
// face's area, L = V / A_max (the length LS-DYNA's solid elements take for their time step: J. O.
// Hallquist, LS-DYNA Theory Manual, section on the time-step size). The faces by their corners,
// a quadrilateral as the four triangles about its centroid, the volume by the divergence theorem
// over those triangles (exact for flat faces); the midside nodes of quadratic elements are left
// out. A volume <= 0 (an element turned inside out) gives 0.

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/element_type.hpp"

namespace partita::fem {

double element_length(ElementType type, const ElementCoordinates& x);

}  // namespace partita::fem
