#pragma once

namespace partita::fem {

// How Hex8 stiffness is integrated.
//   IncompatibleModes (default): Wilson's three incompatible bubble modes per direction
//     (1 - xi^2, 1 - eta^2, 1 - zeta^2) with Taylor, Beresford & Wilson's (1976) constant-
//     Jacobian correction (their derivatives use J0 at the centre, scaled by det J0 / det J,
//     so the patch test passes on distorted meshes), integrated 2x2x2 and statically condensed
//     per element (the "QM6" element). Removes shear locking in bending and volumetric locking
//     up to nu ~ 0.49.
//   Full: plain 2x2x2 Gauss (locks in bending; as CalculiX's C3D8), for comparison.
enum class Hex8Formulation { IncompatibleModes, Full };

}  // namespace partita::fem
