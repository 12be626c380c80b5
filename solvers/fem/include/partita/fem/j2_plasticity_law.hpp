#pragma once
#include "partita/fem/hardening_curve.hpp"
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"
#include "partita/fem/strain_rate_law.hpp"

namespace partita::fem {

// Small-strain J2 (von Mises) plasticity with isotropic hardening, associative flow, backward
// Euler radial return and the consistent (algorithmic) tangent (Simo & Hughes, Computational
// Inelasticity, 1998, chapter 3: the radial return of Box 3.1 and its consistent tangent):
//   eps = sym(F - I), s_tr = 2 G dev(eps - eps_p_n), f = |s_tr| - sqrt(2/3) sigma_y(alpha_n)
//   f <= 0: elastic;  else solve |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha_n + sqrt(2/3) dg) = 0,
//   n = s_tr / |s_tr|, s = s_tr - 2 G dg n, eps_p += dg n, alpha += sqrt(2/3) dg,
//   C_ep = K 1(x)1 + 2 G theta I_dev - 2 G theta_bar n(x)n,
//   theta = 1 - 2 G dg / |s_tr|, theta_bar = 1 / (1 + H / (3 G)) - (1 - theta).
// History per point (14 values): eps_p (xx yy zz xy yz zx, tensor components), alpha, plastic
// work w_p = sum 1/2 (sigma_n + sigma_n+1) : d eps_p (per reference volume; trapezoidal like the
// external work, so a proportional path with linear hardening balances exactly), sigma (xx yy
// zz xy yz zx). W = 1/2 (eps - eps_p) : C : (eps - eps_p) is the stored elastic energy (the
// hardening energy is part of the plastic work).
// With a strain-rate law (CowperSymonds, optional) a dynamic step's return solves for the
// dynamic flow stress sigma_y(alpha) [1 + (d alpha / (dt D))^(1/q)] and the tangent's H is its
// slope along the step (strain_rate_law.hpp); static steps and a law without it are as above.
class J2PlasticityLaw final : public MaterialLaw {
 public:
  J2PlasticityLaw(double youngs_modulus, double poisson_ratio, double density,
                  HardeningCurve hardening, std::optional<CowperSymonds> strain_rate = {});

  std::string_view name() const override { return "j2-plasticity"; }
  bool small_strain() const override { return true; }
  double density() const override { return density_; }
  Material small_strain_material() const override { return elastic_; }
  double dilatational_wave_speed() const override;
  double bulk_modulus() const override { return bulk_; }
  int state_size() const override { return 14; }
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override {
    evaluate_with(f, committed, trial, response, true, MaterialStep{});
  }
  // without the tangent loop (explicit steps)
  void evaluate_stress(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                       MaterialResponse& response) const override {
    evaluate_with(f, committed, trial, response, false, MaterialStep{});
  }
  void evaluate_step(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                     const MaterialStep& step, MaterialResponse& response) const override {
    evaluate_with(f, committed, trial, response, true, step);
  }
  void evaluate_step_stress(const Mat3& f, std::span<const double> committed,
                            std::span<double> trial, const MaterialStep& step,
                            MaterialResponse& response) const override {
    evaluate_with(f, committed, trial, response, false, step);
  }
  double plastic_work_density(std::span<const double> state) const override { return state[7]; }
  double equivalent_plastic_strain(std::span<const double> state) const override {
    return state[6];
  }
  const HardeningCurve& hardening() const { return hardening_; }
  const std::optional<CowperSymonds>& strain_rate() const { return strain_rate_; }

 private:
  Material elastic_;  // E, nu, rho as given
  void evaluate_with(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                     MaterialResponse& response, bool with_tangent,
                     const MaterialStep& step) const;
  double density_ = 0.0, bulk_ = 0.0, shear_ = 0.0;
  HardeningCurve hardening_;
  std::optional<CowperSymonds> strain_rate_;
};

// Its registry entry: "j2-plasticity" from youngs_modulus, poisson_ratio, density and the
// hardening (hardening_parameters()), optionally the strain-rate law (strain_rate_parameters()).
MaterialLawEntry j2_plasticity_law_entry();

}  // namespace partita::fem
