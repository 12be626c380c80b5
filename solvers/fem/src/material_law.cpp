#include "partita/fem/material_law.hpp"

#include <algorithm>
#include <sstream>
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

Material MaterialLaw::small_strain_material() const {
  // K = lambda + 2/3 mu and rho c_d^2 = lambda + 2 mu give mu = 3/4 (rho c_d^2 - K); then
  // E = 9 K mu / (3 K + mu), nu = (3 K - 2 mu) / (2 (3 K + mu))
  const double rho = density(), k = bulk_modulus(), c = dilatational_wave_speed();
  const double mu = 0.75 * (rho * c * c - k);
  return {9.0 * k * mu / (3.0 * k + mu), (3.0 * k - 2.0 * mu) / (2.0 * (3.0 * k + mu)), rho};
}

void MaterialLaw::initialise_state(std::span<double> state) const {
  std::fill(state.begin(), state.end(), 0.0);
}

double MaterialLaw::plastic_work_density(std::span<const double>) const {
  return 0.0;
}

double MaterialLaw::equivalent_plastic_strain(std::span<const double>) const {
  return 0.0;
}

void validate_isotropic_constants(std::string_view law, double e, double nu, double rho) {
  const std::string name(law);
  if (!(e > 0.0)) {
    throw Error(name + ": Young's modulus must be > 0 Pa, got " + std::to_string(e));
  }
  if (!(nu > -1.0 && nu < 0.5)) {
    throw Error(name + ": Poisson's ratio must lie in (-1, 0.5), got " + std::to_string(nu) +
                " (the law is compressible: nu >= 0.5 makes the bulk modulus infinite; use "
                "e.g. 0.45-0.49)");
  }
  if (!(rho >= 0.0)) {
    throw Error(name + ": density must be >= 0 kg/m^3, got " + std::to_string(rho));
  }
}

void require_positive_jacobian(std::string_view law, double j) {
  if (j > 0.0) return;
  std::ostringstream msg;
  msg << law << ": deformation gradient with det F = " << j
      << " <= 0 (material inverted); reduce the load or time step";
  throw Error(msg.str());
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

std::vector<MaterialParameter> isotropic_parameters() {
  return {MaterialParameter::number("youngs_modulus", "Pa", "Young's modulus E")
              .positive()
              .typical(1e5, 1.2e12, "Young's moduli of solids (soft rubber to diamond)")
              .required(),
          MaterialParameter::number("poisson_ratio", "", "Poisson's ratio nu")
              .range(-1.0, 0.5, true)
              .required(),
          MaterialParameter::number("density", "kg/m^3", "mass density rho")
              .positive()
              .typical(10.0, 2.3e4, "densities of solids (polymer foams to osmium)")
              .required()};
}

}  // namespace partita::fem
