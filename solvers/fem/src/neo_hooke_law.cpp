#include "partita/fem/neo_hooke_law.hpp"

#include <cmath>

#include "partita/fem/error.hpp"

namespace partita::fem {

NeoHookeLaw::NeoHookeLaw(double e, double nu, double rho) : elastic_{e, nu, rho}, density_(rho) {
  validate_isotropic_constants("neo-hooke", e, nu, rho);
  lame_ = lame_constants(e, nu);
}

double NeoHookeLaw::dilatational_wave_speed() const {
  return std::sqrt((lame_.lambda + 2.0 * lame_.mu) / density_);
}

double NeoHookeLaw::bulk_modulus() const {
  return lame_.lambda + 2.0 / 3.0 * lame_.mu;
}

void NeoHookeLaw::evaluate(const Mat3& f, std::span<const double>, std::span<double>,
                           MaterialResponse& r) const {
  const double j = f.determinant();
  require_positive_jacobian("neo-hooke", j);
  const double mu = lame_.mu, lambda = lame_.lambda;
  const double log_j = std::log(j);
  const Mat3 finv = f.inverse();
  // P = mu (F - F^-T) + lambda ln J F^-T
  r.stress = mu * (f - finv.transpose()) + lambda * log_j * finv.transpose();
  // A_iJkL = mu d_ik d_JL + (mu - lambda ln J) F^-1_Li F^-1_Jk + lambda F^-1_Ji F^-1_Lk
  const double c = mu - lambda * log_j;
  for (int i = 0; i < 3; ++i) {
    for (int jj = 0; jj < 3; ++jj) {
      for (int k = 0; k < 3; ++k) {
        for (int l = 0; l < 3; ++l) {
          double v = c * finv(l, i) * finv(jj, k) + lambda * finv(jj, i) * finv(l, k);
          if (i == k && jj == l) v += mu;
          r.tangent(3 * i + jj, 3 * k + l) = v;
        }
      }
    }
  }
  // W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2
  r.energy_density = 0.5 * mu * (f.squaredNorm() - 3.0) - mu * log_j + 0.5 * lambda * log_j * log_j;
}

MaterialLawEntry neo_hooke_law_entry() {
  return {"neo-hooke",
          "compressible, finite strain, W = mu/2 (tr C - 3) - mu ln J + lambda/2 ln^2 J",
          isotropic_parameters(),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<NeoHookeLaw>(p.real("youngs_modulus"),
                                                 p.real("poisson_ratio"), p.real("density"));
          }};
}

}  // namespace partita::fem
