#include "partita/fem/decoupled_neo_hooke_law.hpp"

#include <cmath>

#include "partita/fem/error.hpp"

namespace partita::fem {

DecoupledNeoHookeLaw::DecoupledNeoHookeLaw(double e, double nu, double rho) : elastic_{e, nu, rho}, density_(rho) {
  validate_isotropic_constants("neo-hooke-decoupled", e, nu, rho);
  mu_ = e / (2.0 * (1.0 + nu));
  kappa_ = e / (3.0 * (1.0 - 2.0 * nu));
}

double DecoupledNeoHookeLaw::dilatational_wave_speed() const {
  return std::sqrt((kappa_ + 4.0 / 3.0 * mu_) / density_);
}

void DecoupledNeoHookeLaw::evaluate(const Mat3& f, std::span<const double>, std::span<double>,
                                    MaterialResponse& r) const {
  const double j = f.determinant();
  require_positive_jacobian("neo-hooke-decoupled", j);
  const Mat3 finv = f.inverse();
  const double i1 = f.squaredNorm();
  const double a = mu_ * std::pow(j, -2.0 / 3.0);
  const double b = 0.5 * kappa_ * (j * j - 1.0);
  // P = mu J^(-2/3) (F - I1/3 F^-T) + kappa/2 (J^2 - 1) F^-T
  r.stress = a * (f - i1 / 3.0 * finv.transpose()) + b * finv.transpose();
  // A_iJkL (see the header)
  for (int i = 0; i < 3; ++i) {
    for (int jj = 0; jj < 3; ++jj) {
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          double v =
              a * (-2.0 / 3.0 * f(k, l) * finv(jj, i) + i1 / 3.0 * finv(jj, k) * finv(l, i)) -
              2.0 / 3.0 * a * finv(l, k) * (f(i, jj) - i1 / 3.0 * finv(jj, i)) +
              kappa_ * j * j * finv(l, k) * finv(jj, i) - b * finv(jj, k) * finv(l, i);
          if (i == k && jj == l) v += a;
          r.tangent(3 * i + jj, 3 * k + l) = v;
        }
      }
    }
  }
  // W = mu/2 (J^(-2/3) I1 - 3) + kappa/4 (J^2 - 1 - 2 ln J)
  r.energy_density = 0.5 * mu_ * (std::pow(j, -2.0 / 3.0) * i1 - 3.0) +
                     0.25 * kappa_ * (j * j - 1.0 - 2.0 * std::log(j));
}

MaterialLawEntry decoupled_neo_hooke_law_entry() {
  return {"neo-hooke-decoupled", "W = mu/2 (I1_bar - 3) + kappa/4 (J^2 - 1 - 2 ln J)",
          isotropic_parameters(),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<DecoupledNeoHookeLaw>(
                p.real("youngs_modulus"), p.real("poisson_ratio"), p.real("density"));
          }};
}

}  // namespace partita::fem
