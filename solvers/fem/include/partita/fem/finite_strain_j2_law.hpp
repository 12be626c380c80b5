#pragma once
#include "partita/fem/hardening_curve.hpp"
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"
#include "partita/fem/strain_rate_law.hpp"

namespace partita::fem {

// Finite-strain J2 plasticity: multiplicative split F = F_e F_p, Hencky (logarithmic) elastic
// strains, exponential-map return in principal space (Eterovic & Bathe, IJNME 30 (1990)
// 1099-1114; Simo, CMAME 99 (1992) 61-112; de Souza Neto, Peric & Owen, Computational Methods
// for Plasticity, 2008, chapter 14):
//   b_e_tr = F C_p_n^-1 F^T = sum lambda_a^2 n_a n_a,  eps_tr = ln(lambda_a) (principal),
//   the small-strain radial return (J2PlasticityLaw, same hardening) on eps_tr gives the
//   principal Kirchhoff stresses tau_a and eps_e; b_e = sum exp(2 eps_e,a) n_a n_a,
//   C_p^-1 = F^-1 b_e F^-T,  P = tau F^-T.
// Stored energy W = 1/2 K tr(eps_e)^2 + G |dev eps_e|^2; plastic work w_p += 1/2 (tau_n +
// tau_n+1) : d eps_p (per reference volume). For coaxial (fixed principal directions) paths the
// model is the small-strain one in log strain and Kirchhoff stress, exactly.
// Tangent: dP/dF by central differences of the return map (perturbation h = 1e-7 on each
// F_kL; Miehe, CMAME 134 (1996) 223-240): accurate to ~1e-9 relative, so Newton converges
// quadratically down to that level.
// Evaluation: with b_e_tr = c (I + Y), c = tr(b_e_tr) / 3, the log and exp are power series
// of the traceless Y (and of the deviatoric elastic strain after the return), reduced to
// a I + b Y + c Y^2 by Cayley-Hamilton: no eigen-decomposition, exact for equal principal
// stretches, as many terms as keep the tail under ~1e-17 (a handful for metals, whose elastic
// strains are ~1e-3); an elastic step keeps C_p^-1 as it was (b_e = b_e_tr). Beyond a
// spectral radius of Y of kSeriesRadius (large elastic strains, e.g. a rubber-like E / sigma_y)
// the principal-space return through Eigen's eigen-solver (spectral_stress) is used. The two
// agree to round-off (test_finite_strain_j2_fast.cpp).
// Strain-rate hardening (CowperSymonds, optional): a dynamic step's return on the log strains is
// the small-strain law's viscoplastic one (strain_rate_law.hpp), so the Kirchhoff stress follows
// sigma_y(alpha) [1 + (d alpha / (dt D))^(1/q)]; static steps and a law without it are as above.
// History (14 values): C_p^-1 (xx yy zz xy yz zx), alpha, w_p, tau (xx yy zz xy yz zx).
class FiniteStrainJ2Law final : public MaterialLaw {
 public:
  FiniteStrainJ2Law(double youngs_modulus, double poisson_ratio, double density,
                    HardeningCurve hardening, std::optional<CowperSymonds> strain_rate = {});

  std::string_view name() const override { return "j2-plasticity-finite-strain"; }
  double density() const override { return density_; }
  Material small_strain_material() const override { return elastic_; }
  double dilatational_wave_speed() const override;
  double bulk_modulus() const override { return bulk_; }
  int state_size() const override { return kStateSize; }
  void initialise_state(std::span<double> state) const override;
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override {
    evaluate_step(f, committed, trial, MaterialStep{}, response);
  }
  // the stress alone: without the 18 return maps of the tangent's difference quotients
  void evaluate_stress(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                       MaterialResponse& response) const override {
    stress(f, committed, trial, response.stress, response.energy_density, MaterialStep{});
  }
  void evaluate_step(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                     const MaterialStep& step, MaterialResponse& response) const override;
  void evaluate_step_stress(const Mat3& f, std::span<const double> committed,
                            std::span<double> trial, const MaterialStep& step,
                            MaterialResponse& response) const override {
    stress(f, committed, trial, response.stress, response.energy_density, step);
  }
  // The same return in principal space through an eigen-decomposition of b_e_tr (Eigen's
  // iterative solver): the path beyond the series' bound, public as the reference the tests
  // compare the series path with. P and W at F from the committed history; writes the trial
  // history.
  void spectral_stress(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                       Mat3& p, double& energy, const MaterialStep& step = {}) const;
  // The series path's bound on the spectral radius of the traceless part of b_e_tr / c.
  static constexpr double kSeriesRadius = 0.25;
  double plastic_work_density(std::span<const double> state) const override { return state[7]; }
  double equivalent_plastic_strain(std::span<const double> state) const override {
    return state[6];
  }
  const std::optional<CowperSymonds>& strain_rate() const { return strain_rate_; }

 private:
  Material elastic_;  // E, nu, rho as given
  static constexpr int kStateSize = 14;
  // P and W at F from the committed history; writes the trial history.
  void stress(const Mat3& f, std::span<const double> committed, std::span<double> trial, Mat3& p,
              double& energy, const MaterialStep& step) const;
  // The radial return's dg on the log strains for a trial norm |s_tr| (0 when elastic): the
  // hardening's, or with a strain-rate law in a dynamic step the viscoplastic one.
  double return_increment(double s_norm, double alpha_n, const MaterialStep& step) const;
  double density_ = 0.0, bulk_ = 0.0, shear_ = 0.0;
  HardeningCurve hardening_;
  std::optional<CowperSymonds> strain_rate_;
};

// Its registry entry: "j2-plasticity-finite-strain" from youngs_modulus, poisson_ratio, density
// and the hardening (hardening_parameters()), optionally the strain-rate law
// (strain_rate_parameters()).
MaterialLawEntry finite_strain_j2_law_entry();

}  // namespace partita::fem
