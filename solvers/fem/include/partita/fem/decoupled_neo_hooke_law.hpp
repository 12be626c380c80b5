#pragma once
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

// Compressible Neo-Hooke with an isochoric / volumetric split (Miehe 1994; Holzapfel 2000,
// section 6.5; the form of the deal.II code-gallery Cook's membrane by Pelteret & McBride 2016):
//   W = mu/2 (I1_bar - 3) + kappa/4 (J^2 - 1 - 2 ln J),   I1_bar = J^(-2/3) tr C,
//   P = mu J^(-2/3) (F - I1/3 F^-T) + kappa/2 (J^2 - 1) F^-T,
//   A_iJkL = a (d_ik d_JL - 2/3 F_kL F^-1_Ji + I1/3 F^-1_Jk F^-1_Li)
//            - 2/3 a F^-1_Lk (F_iJ - I1/3 F^-1_Ji) + kappa J^2 F^-1_Lk F^-1_Ji
//            - b F^-1_Jk F^-1_Li,   a = mu J^(-2/3), b = kappa/2 (J^2 - 1),
// with mu = E / (2 (1 + nu)) and kappa = E / (3 (1 - 2 nu)). Same small-strain limit as
// NeoHookeLaw, different at finite strain. Rejects nu >= 0.5 (kappa infinite).
class DecoupledNeoHookeLaw final : public MaterialLaw {
 public:
  DecoupledNeoHookeLaw(double youngs_modulus, double poisson_ratio, double density);

  std::string_view name() const override { return "neo-hooke-decoupled"; }
  double density() const override { return density_; }
  Material small_strain_material() const override { return elastic_; }
  double dilatational_wave_speed() const override;
  double bulk_modulus() const override { return kappa_; }
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override;
  double mu() const { return mu_; }

 private:
  Material elastic_;  // E, nu, rho as given
  double mu_ = 0.0, kappa_ = 0.0, density_ = 0.0;
};

// Its registry entry: "neo-hooke-decoupled" from youngs_modulus, poisson_ratio, density.
MaterialLawEntry decoupled_neo_hooke_law_entry();

}  // namespace partita::fem
