// A plugin that adds a material law of its own to the FE solver
// (tests/app/test_material_law_plugin.cpp; docs/extending.md shows it). One source, one variant
// per definition:
//   PLUGIN_SAINT_VENANT_KIRCHHOFF  the law "saint-venant-kirchhoff" (below)
//   PLUGIN_BUILTIN_LAW_NAME        a law registered under a built-in law's name (neo-hooke)
//   PLUGIN_OTHER_UNIT              a law whose density is declared in g/cm^3, where the built-in
//                                  laws' is in kg/m^3 (one key, one unit)
//
// Saint Venant-Kirchhoff: the isotropic law of linear elasticity written in the Green-Lagrange
// strain E = (F^T F - I) / 2, valid for large rotations and moderate strains:
//   W = lambda/2 (tr E)^2 + mu tr(E^2),  S = dW/dE = lambda tr(E) I + 2 mu E,  P = F S,
//   A_iJkL = dP_iJ / dF_kL = delta_ik S_JL + F_iM C_MJNL F_kN,
//   C_MJNL = lambda delta_MJ delta_NL + mu (delta_MN delta_JL + delta_ML delta_JN).
#include <cmath>
#include <memory>

#include "partita/adapters/material_laws.hpp"
#include "partita/coupling/plugin.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace {

using partita::fem::Mat3;
using partita::fem::MaterialLaw;
using partita::fem::MaterialLawEntry;
using partita::fem::MaterialParameter;
using partita::fem::MaterialParameters;
using partita::fem::MaterialResponse;

class SaintVenantKirchhoffLaw final : public MaterialLaw {
 public:
  SaintVenantKirchhoffLaw(double youngs_modulus, double poisson_ratio, double density)
      : density_(density),
        lambda_(youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))),
        mu_(youngs_modulus / (2.0 * (1.0 + poisson_ratio))) {}

  std::string_view name() const override { return "saint-venant-kirchhoff"; }
  double density() const override { return density_; }
  double dilatational_wave_speed() const override {
    return std::sqrt((lambda_ + 2.0 * mu_) / density_);
  }
  double bulk_modulus() const override { return lambda_ + 2.0 / 3.0 * mu_; }

  void evaluate(const Mat3& f, std::span<const double>, std::span<double>,
                MaterialResponse& r) const override {
    const Mat3 e = 0.5 * (f.transpose() * f - Mat3::Identity());
    const Mat3 s = lambda_ * e.trace() * Mat3::Identity() + 2.0 * mu_ * e;
    r.stress = f * s;
    r.energy_density = 0.5 * lambda_ * e.trace() * e.trace() + mu_ * (e * e).trace();
    const auto delta = [](int a, int b) { return a == b ? 1.0 : 0.0; };
    for (int i = 0; i < 3; ++i)
      for (int jj = 0; jj < 3; ++jj)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            // F_iM C_MJNL F_kN = lambda (F_iJ F_kL) + mu ((F F^T)_ik delta_JL + F_iL F_kJ)
            double a = delta(i, k) * s(jj, l);
            a += lambda_ * f(i, jj) * f(k, l);
            a += mu_ * ((f.row(i).dot(f.row(k))) * delta(jj, l) + f(i, l) * f(k, jj));
            r.tangent(3 * i + jj, 3 * k + l) = a;
          }
  }

 private:
  double density_, lambda_, mu_;
};

// The law's parameters, each with its unit, range, typical values and doc; the case keys of
// the FEM's material section.
std::vector<MaterialParameter> parameters(const char* density_unit) {
  return {MaterialParameter::number("youngs_modulus", "Pa", "Young's modulus E")
              .positive()
              .typical(1e5, 1.2e12, "Young's moduli of solids (soft rubber to diamond)")
              .required(),
          MaterialParameter::number("poisson_ratio", "", "Poisson's ratio nu")
              .range(-1.0, 0.5, true)
              .required(),
          MaterialParameter::number("density", density_unit, "mass density rho").positive().required()};
}

MaterialLawEntry saint_venant_kirchhoff_entry(std::string name, const char* density_unit) {
  return {std::move(name),
          "finite strain, S = lambda tr(E) I + 2 mu E (large rotations, moderate strains; from "
          "a plugin)",
          parameters(density_unit),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<SaintVenantKirchhoffLaw>(
                p.real("youngs_modulus"), p.real("poisson_ratio"), p.real("density"));
          }};
}

}  // namespace

// No solver, mapper or scheme: the entry point is still required, and registers nothing.
PARTITA_PLUGIN(registries) {
  (void)registries;
}

PARTITA_PLUGIN_MATERIAL_LAWS(laws) {
#if defined(PLUGIN_BUILTIN_LAW_NAME)
  laws.add(saint_venant_kirchhoff_entry("neo-hooke", "kg/m^3"));
#elif defined(PLUGIN_OTHER_UNIT)
  laws.add(saint_venant_kirchhoff_entry("saint-venant-kirchhoff-cgs", "g/cm^3"));
#else
  laws.add(saint_venant_kirchhoff_entry("saint-venant-kirchhoff", "kg/m^3"));
#endif
}
