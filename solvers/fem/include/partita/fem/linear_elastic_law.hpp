#pragma once
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

// Isotropic linear elasticity at small strain: eps = sym(F - I), sigma = lambda tr(eps) I +
// 2 mu eps, W = 1/2 eps : C : eps. The structural solver recognises it and keeps the linear
// path (K assembled and factorised once, Hex8 incompatible modes).
class LinearElasticLaw final : public MaterialLaw {
 public:
  explicit LinearElasticLaw(const Material& material);

  std::string_view name() const override { return "linear-elastic"; }
  bool small_strain() const override { return true; }
  double density() const override { return material_.density; }
  Material small_strain_material() const override { return material_; }
  double dilatational_wave_speed() const override;
  double bulk_modulus() const override;
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override;
  const Material& material() const { return material_; }

 private:
  Material material_;
  LameConstants lame_;
  Matrix9 c_;
};

// Its registry entry: "linear-elastic" from youngs_modulus, poisson_ratio, density.
MaterialLawEntry linear_elastic_law_entry();

}  // namespace partita::fem
