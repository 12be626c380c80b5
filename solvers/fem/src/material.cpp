#include "partita/fem/material.hpp"

#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

void Material::validate() const {
  if (!(youngs_modulus > 0.0)) {
    throw Error("material: Young's modulus must be > 0 Pa, got " + std::to_string(youngs_modulus));
  }
  if (!(poisson_ratio > -1.0 && poisson_ratio < 0.5)) {
    throw Error("material: Poisson's ratio must lie in (-1, 0.5), got " +
                std::to_string(poisson_ratio));
  }
  if (!(density >= 0.0)) {
    throw Error("material: density must be >= 0 kg/m^3, got " + std::to_string(density));
  }
}

Matrix6 Material::elasticity_matrix() const {
  const double e = youngs_modulus;
  const double nu = poisson_ratio;
  const double lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double mu = e / (2.0 * (1.0 + nu));
  Matrix6 d = Matrix6::Zero();
  // D = lambda 1 (x) 1 + 2 mu I on the normal block, mu on the engineering shears.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) d(i, j) = lambda;
    d(i, i) += 2.0 * mu;
    d(3 + i, 3 + i) = mu;
  }
  return d;
}

}  // namespace partita::fem
