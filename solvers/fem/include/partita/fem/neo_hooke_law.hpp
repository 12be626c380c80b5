#pragma once
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

// Compressible Neo-Hooke, total Lagrangian (e.g. Bonet & Wood, Nonlinear Continuum Mechanics
// for Finite Element Analysis, 2nd ed. 2008, section 6.4.3):
//   W(C) = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,   C = F^T F, J = det F,
//   S = mu (I - C^-1) + lambda ln J C^-1,  P = F S = mu (F - F^-T) + lambda ln J F^-T,
//   A_iJkL = dP_iJ/dF_kL = mu d_ik d_JL + (mu - lambda ln J) F^-1_Li F^-1_Jk
//            + lambda F^-1_Ji F^-1_Lk.
// lambda and mu are the Lame constants of E and nu (the law reduces to Hooke's at small
// strain). Rejects E <= 0, nu outside (-1, 0.5) (nu >= 0.5 would make lambda infinite) and
// rho < 0. J <= 0 (an inverted point) throws Error.
class NeoHookeLaw final : public MaterialLaw {
 public:
  NeoHookeLaw(double youngs_modulus, double poisson_ratio, double density);

  std::string_view name() const override { return "neo-hooke"; }
  double density() const override { return density_; }
  Material small_strain_material() const override { return elastic_; }
  double dilatational_wave_speed() const override;
  double bulk_modulus() const override;
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override;
  double lambda() const { return lame_.lambda; }
  double mu() const { return lame_.mu; }

 private:
  Material elastic_;  // E, nu, rho as given
  LameConstants lame_;
  double density_ = 0.0;
};

// Its registry entry: "neo-hooke" from youngs_modulus, poisson_ratio, density.
MaterialLawEntry neo_hooke_law_entry();

}  // namespace partita::fem
