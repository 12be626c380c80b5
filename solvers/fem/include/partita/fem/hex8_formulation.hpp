#pragma once

namespace partita::fem {

// How Hex8 stiffness is integrated.
//   IncompatibleModes (default): Wilson's three incompatible bubble modes per direction
//     (1 - xi^2, 1 - eta^2, 1 - zeta^2) with Taylor, Beresford & Wilson's (1976) constant-
//     Jacobian correction (their derivatives use J0 at the centre, scaled by det J0 / det J,
//     so the patch test passes on distorted meshes), integrated 2x2x2 and statically condensed
//     per element (the "QM6" element). Removes shear locking in bending and volumetric locking
//     up to nu ~ 0.49. On the nonlinear path the same modes enter the deformation gradient as
//     enhanced assumed strains (EAS, Simo & Armero 1992; Simo, Armero & Taylor 1993: F = I +
//     grad u + sum_J alpha_J (x) (j0/j) xi_J (J0^-1)_J, alpha condensed per element by a local
//     Newton), with 6 Gauss points through the thickness of thin elements (see
//     MaterialContribution): no element changes when the material does.
//   Full: plain 2x2x2 Gauss (locks in bending and, on the nonlinear path, under plastic or
//     near-incompressible flow; as CalculiX's C3D8), for comparison.
//   FBar: the nonlinear path's Hex8 against volumetric locking: F_bar = (J_bar / J)^(1/3) F at
//     each of the 2x2x2 points (de Souza Neto, Peric, Dutko & Owen 1996, with the element's
//     volume ratio J_bar = v / V in place of det F at the centre), internal force and tangent
//     the derivatives of int W(F_bar) dV (see MaterialContribution); still locks in bending of
//     thin parts. The linear path rejects it (its incompatible-mode Hex8 does not lock).
//   Reduced: the explicit plate element (central difference only: no tangent): one point in the
//     plane and a line of Gauss points through the thickness (6 in plate-like elements, 2 in
//     others),
//     hourglass stabilisation of the two modes the line does not see (xi eta and xi eta zeta,
//     Flanagan & Belytschko 1981's projection, stiffnesses of Belytschko & Bindeman 1993's
//     assumed-strain kind) and one enhanced thickness strain against Poisson thickness locking
//     (updated once per step). See MaterialContribution.
enum class Hex8Formulation { IncompatibleModes, Full, FBar, Reduced };

}  // namespace partita::fem
