#include "partita/fem/material_law.hpp"

#include <algorithm>

namespace partita::fem {

void MaterialLaw::initialise_state(std::span<double> state) const {
  std::fill(state.begin(), state.end(), 0.0);
}

double MaterialLaw::plastic_work_density(std::span<const double>) const {
  return 0.0;
}

double MaterialLaw::equivalent_plastic_strain(std::span<const double>) const {
  return 0.0;
}

LameConstants lame_constants(double e, double nu) {
  return {e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu))};
}

Matrix9 isotropic_elasticity_tensor(double lambda, double mu) {
  Matrix9 c = Matrix9::Zero();
  // C_iJkL = lambda d_iJ d_kL + mu (d_ik d_JL + d_iL d_Jk)
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          double v = 0.0;
          if (i == j && k == l) v += lambda;
          if (i == k && j == l) v += mu;
          if (i == l && j == k) v += mu;
          c(3 * i + j, 3 * k + l) = v;
        }
      }
    }
  }
  return c;
}

}  // namespace partita::fem
