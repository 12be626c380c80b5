#pragma once
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

// Isotropic hardening: the uniaxial yield stress sigma_y(alpha) as a function of the equivalent
// plastic strain alpha = int sqrt(2/3) |d eps_p|.
//   linear(sigma_y0, H):  sigma_y = sigma_y0 + H alpha  (H >= 0)
//   tabulated({(alpha_i, sigma_i)}): piecewise linear through the points; alpha_0 = 0, alpha
//     strictly increasing, sigma non-decreasing (no softening); constant beyond the last point.
// Throws Error on a negative or zero initial yield stress, H < 0, a table with fewer than one
// point, not starting at alpha = 0, not strictly increasing in strain or decreasing in stress.
class HardeningCurve {
 public:
  static HardeningCurve linear(double initial_yield_stress, double hardening_modulus);
  static HardeningCurve tabulated(std::vector<std::pair<double, double>> points);

  double yield_stress(double alpha) const;  // sigma_y(alpha) [Pa]
  double slope(double alpha) const;         // H(alpha) = d sigma_y / d alpha [Pa]
  double initial_yield_stress() const;
  // The plastic multiplier dg of a radial return: the root of
  //   trial_norm - 2 G dg - sqrt(2/3) sigma_y(alpha_n + sqrt(2/3) dg) = 0
  // (trial_norm = |s_tr| > sqrt(2/3) sigma_y(alpha_n)), by Newton (exact in one step for linear
  // hardening, a few steps across table segments). Throws Error if it does not converge.
  double return_map_increment(double shear_modulus, double trial_norm, double alpha_n) const;

 private:
  HardeningCurve() = default;
  bool linear_ = true;
  double sigma0_ = 0.0, h_ = 0.0;
  std::vector<std::pair<double, double>> points_;
};

// The hardening parameters of the J2 laws' registry entries: yield_stress and hardening_modulus
// (linear), or hardening_table (rows of plastic strain, yield stress: tabulated).
std::vector<MaterialParameter> hardening_parameters();
// The rules between them (the J2 entries' check): one of the two forms, not both; every yield
// stress below youngs_modulus (a yield strain of 1 or more is a unit left out, not a material);
// a table that HardeningCurve::tabulated accepts. The first broken, naming `law`, or nothing.
std::optional<MaterialParameterIssue> check_hardening(std::string_view law,
                                                      const MaterialParameters& p);
// The curve those parameters give (Error with check_hardening's message when one is broken).
HardeningCurve hardening_curve_from(std::string_view law, const MaterialParameters& p);

}  // namespace partita::fem
