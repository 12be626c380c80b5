#pragma once
#include "partita/fem/types.hpp"

namespace partita::fem {

// Isotropic linear-elastic material (SI units). Defaults: steel of the seed plate.
struct Material {
  double youngs_modulus = 250.0e9;  // E [Pa]
  double poisson_ratio = 0.3;       // nu [-], -1 < nu < 0.5
  double density = 7850.0;          // rho [kg/m^3]

  // Throws Error when E <= 0, nu outside (-1, 0.5) or rho < 0.
  void validate() const;
  // sigma = D eps in Voigt order xx yy zz xy yz zx (engineering shear strains):
  // D = lambda 1 (x) 1 + 2 mu I, lambda = E nu/((1+nu)(1-2nu)), mu = E/(2(1+nu)).
  Matrix6 elasticity_matrix() const;
};

}  // namespace partita::fem
