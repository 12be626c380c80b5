#pragma once
#include "partita/fem/types.hpp"

namespace partita::fem {

// What a material law returns at one quadrature point.
struct MaterialResponse {
  // First Piola-Kirchhoff stress P [Pa] (small-strain laws: the Cauchy stress sigma).
  Mat3 stress = Mat3::Zero();
  // A = dP/dF, A(3 i + J, 3 k + L) = dP_iJ / dF_kL (small strain: the elasticity tensor C).
  Matrix9 tangent = Matrix9::Zero();
  // Stored (recoverable) energy density W [J/m^3] per reference volume.
  double energy_density = 0.0;
};

}  // namespace partita::fem
