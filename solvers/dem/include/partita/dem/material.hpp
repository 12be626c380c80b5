#pragma once
// Bulk properties of one material (particles, planes and meshes all refer to a material id).

namespace partita::dem {

struct Material {
  double youngs_modulus = 0.0;  ///< E [Pa], > 0
  double poisson_ratio = 0.0;   ///< nu [-], in (-1, 0.5)
  double density = 0.0;         ///< rho [kg/m^3], > 0 (used for particles; ignored for walls)
};

}  // namespace partita::dem
