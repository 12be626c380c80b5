// The FEM participant's material (fem_material.hpp): its spec and what the case's values make of
// a model.

#include "fem_material.hpp"

#include <fmt/format.h>

#include "fem_rupture.hpp"
#include "partita/fem/error.hpp"

namespace partita::adapters {

namespace {

using config::Node;
using config::Spec;

// Yield stresses of structural materials: soft polymers (about 1 MPa) to maraging and
// high-strength steels (2-3 GPa); outside, a warning (a unit left out, most likely).
constexpr double kYieldLow = 1e5, kYieldHigh = 1e10;
constexpr const char* kYieldWhat = "yield stresses of solids (polymer foams to hardened steel)";

// The law of material: {model: ...} with the elastic constants read once (`elastic`); nullptr for
// linear-elastic (the Material path).
std::shared_ptr<const fem::MaterialLaw> build_law(const Node& mat, const fem::Material& elastic) {
  const std::string model = mat.string("model");
  const double e = elastic.youngs_modulus, nu = elastic.poisson_ratio;
  const double rho = elastic.density;
  if (model == "neo-hooke") return std::make_shared<fem::NeoHookeLaw>(e, nu, rho);
  if (model == "neo-hooke-decoupled")
    return std::make_shared<fem::DecoupledNeoHookeLaw>(e, nu, rho);
  if (model != "j2-plasticity" && model != "j2-plasticity-finite-strain") return nullptr;
  const auto make = [&](fem::HardeningCurve curve) -> std::shared_ptr<const fem::MaterialLaw> {
    if (model == "j2-plasticity")
      return std::make_shared<fem::J2PlasticityLaw>(e, nu, rho, std::move(curve));
    return std::make_shared<fem::FiniteStrainJ2Law>(e, nu, rho, std::move(curve));
  };
  // A yield stress at or above Young's modulus is a yield strain of 1 or more: a unit left out
  // (a bare number is in Pa), not a material.
  const auto check_yield = [&](const Node& at, double sigma_y) {
    if (sigma_y < e) return;
    std::string hint;
    if (mat["youngs_modulus"].is_scalar() &&
        config::parse_quantity(mat["youngs_modulus"].yaml().Scalar(), "").has_value())
      hint = "; a number without a unit is in Pa: write the unit, e.g. youngs_modulus: " +
             mat["youngs_modulus"].yaml().Scalar() + " GPa";
    at.fail(fmt::format(
        "yield stress {:.6g} Pa is not below Young's modulus {:.6g} Pa (youngs_modulus at line "
        "{}): a yield strain sigma_y / E = {:.3g}, where solids yield at 1e-4 to 1e-1{}",
        sigma_y, e, mat["youngs_modulus"].location().line, sigma_y / e, hint));
  };
  if (mat.has("hardening_table")) {
    if (mat.has("yield_stress"))
      mat["yield_stress"].fail(
          "give either yield_stress (and hardening_modulus) or hardening_table");
    std::vector<std::pair<double, double>> points;
    for (const Node& p : mat["hardening_table"].items()) {
      points.emplace_back(p.real("plastic_strain"), p.real("yield_stress"));
      check_yield(p["yield_stress"], points.back().second);
    }
    try {
      return make(fem::HardeningCurve::tabulated(points));
    } catch (const fem::Error& error) {
      mat["hardening_table"].fail(error.what());  // at the table's line, not the participant's
    }
  }
  if (!mat.has("yield_stress"))
    mat.fail(model +
             " needs 'yield_stress' (and optionally 'hardening_modulus') or "
             "'hardening_table'");
  check_yield(mat["yield_stress"], mat.real("yield_stress"));
  return make(fem::HardeningCurve::linear(mat.real("yield_stress"), mat.real("hardening_modulus")));
}

}  // namespace

std::shared_ptr<config::Spec> fem_material_spec() {
  auto hardening_point =
      std::make_shared<Spec>("hardening_point", "a point of the hardening curve");
  hardening_point->real("plastic_strain", "equivalent plastic strain (first point: 0)")
      .non_negative()
      .required();
  hardening_point->real("yield_stress", "uniaxial yield stress there")
      .unit("Pa")
      .positive()
      .typical(kYieldLow, kYieldHigh, kYieldWhat)
      .required();
  auto material = std::make_shared<Spec>(
      "material", "isotropic material: linear elastic, compressible Neo-Hooke or J2 plasticity");
  material
      ->choice("model",
               "linear-elastic (small strain, the fast linear path), neo-hooke (compressible, "
               "finite strain, W = mu/2 (tr C - 3) - mu ln J + lambda/2 ln^2 J), "
               "neo-hooke-decoupled (W = mu/2 (I1_bar - 3) + kappa/4 (J^2 - 1 - 2 ln J)), "
               "j2-plasticity (small strain, isotropic hardening) or j2-plasticity-finite-strain "
               "(multiplicative, logarithmic strains)",
               {"linear-elastic", "neo-hooke", "neo-hooke-decoupled", "j2-plasticity",
                "j2-plasticity-finite-strain"})
      .def("linear-elastic");
  material->real("youngs_modulus", "Young's modulus E")
      .unit("Pa")
      .positive()
      .typical(config::kSolidModulusLow, config::kSolidModulusHigh, config::kSolidModulusWhat)
      .required();
  material->real("poisson_ratio", "Poisson's ratio nu").range(-1.0, 0.5, true).required();
  material->real("density", "mass density rho")
      .unit("kg/m^3")
      .positive()
      .typical(config::kSolidDensityLow, config::kSolidDensityHigh, config::kSolidDensityWhat)
      .required();
  material->real("yield_stress", "j2-plasticity: initial uniaxial yield stress (below E)")
      .unit("Pa")
      .positive()
      .typical(kYieldLow, kYieldHigh, kYieldWhat);
  material
      ->real("hardening_modulus", "j2-plasticity: linear isotropic hardening d sigma_y / d eps_p")
      .unit("Pa")
      .non_negative()
      .def(0.0);
  material->list("hardening_table",
                 "j2-plasticity: tabulated hardening instead of yield_stress and hardening_modulus "
                 "(piecewise linear, flat beyond the last point)",
                 hardening_point);
  material->section("failure", "rupture (j2-plasticity)", fem_failure_spec());
  return material;
}

fem::Model build_fem_model(fem::Mesh mesh, const config::Node& mat) {
  const fem::Material elastic{mat.real("youngs_modulus"), mat.real("poisson_ratio"),
                              mat.real("density")};
  fem::Model model(std::move(mesh), elastic);
  if (auto law = build_law(mat, elastic)) model.set_material_law(std::move(law));
  model.set_failure_criterion(build_failure_criterion(mat));
  return model;
}

}  // namespace partita::adapters
