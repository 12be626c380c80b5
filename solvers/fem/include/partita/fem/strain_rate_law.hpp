#pragma once
#include <optional>
#include <string_view>
#include <vector>

#include "partita/fem/hardening_curve.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/material_law_registry.hpp"

namespace partita::fem {

// Strain-rate hardening of the J2 laws, Cowper-Symonds: the dynamic flow stress
//   sigma_y,dyn = sigma_y(alpha) [1 + (alpha_dot / D)^(1/q)]
// with alpha_dot the equivalent plastic strain rate, D [1/s] and q [-] material constants
// (G. R. Cowper & P. S. Symonds, Strain-hardening and strain-rate effects in the impact loading
// of cantilever beams, Brown University, Division of Applied Mathematics, Tech. Rep. 28, 1957;
// N. Jones, Structural Impact, Cambridge University Press, 1989/2012, chapter 8, whose table of
// constants gives mild steel D = 40.4 1/s, q = 5). Ship-collision analyses use the same mild-steel
// values (e.g. J. K. Paik & A. K. Thayamballi, Ultimate Limit State Design of Steel-Plated
// Structures, Wiley 2003; verify the table there), with larger D for higher-strength steels.
//
// Rate measure: the equivalent PLASTIC strain rate of the step, alpha_dot = d alpha / dt (the
// viscoplastic, consistent form; LS-DYNA's *MAT_PIECEWISE_LINEAR_PLASTICITY with its VP = 1
// option works the same way, where VP = 0 instead scales the yield stress by the total strain
// rate). The backward-Euler return then solves, for the plastic multiplier dg
// (d alpha = sqrt(2/3) dg),
//   |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha_n + d alpha) [1 + (d alpha / (dt D))^(1/q)] = 0,
// written in x = (d alpha / (dt D))^(1/q) (d alpha = dt D x^q), where it is smooth at x = 0 for
// q >= 1 (in dg its slope is infinite at 0): bracketed Newton on [0, f_tr / (sqrt(2/3)
// sigma_y(alpha_n))] (f_tr = |s_tr| - sqrt(2/3) sigma_y(alpha_n): the residual is f_tr > 0 at the
// lower end and <= 0 at the upper), bisection when a Newton step leaves the bracket. The
// algorithmic tangent is the radial return's with the hardening modulus H replaced by the slope
// of the dynamic flow stress along the step,
//   H_eff = d sigma_y,dyn / d alpha = H(alpha) (1 + x) + sigma_y(alpha) x^(1 - q) / (q dt D).
// Time: MaterialStep. In a static analysis (step.dynamic false) the rate term is off and the law
// is the rate-independent one; in a dynamic analysis with dt = 0 (an evaluation at the committed
// instant itself) there is no time for viscous flow and the response is elastic, which is the
// limit of the return above as dt -> 0 (an overstress of the committed state stays as it was).
class CowperSymonds {
 public:
  // Error unless D > 0 and q > 0.
  CowperSymonds(double d, double q);
  double d() const { return d_; }
  double q() const { return q_; }
  // 1 + (rate / D)^(1/q) for an equivalent plastic strain rate >= 0 [1/s]
  double factor(double rate) const;

  struct Return {
    double dg = 0.0;     // the plastic multiplier (d alpha = sqrt(2/3) dg)
    double slope = 0.0;  // H_eff: d sigma_y,dyn / d alpha at the solution
  };
  // The return above for a plastic trial (f_tr > 0) and dt > 0. Error if it does not converge.
  Return return_map(const HardeningCurve& hardening, double shear_modulus, double trial_norm,
                    double alpha_n, double dt) const;

 private:
  double d_ = 0.0, q_ = 0.0;
};

// The registry's keys of the strain-rate law: cowper_symonds_d [1/s] and cowper_symonds_q [-],
// both optional (without them the law is rate-independent).
std::vector<MaterialParameter> strain_rate_parameters();
// Both keys or neither, naming `law` and the key that is missing; nothing when the rule holds.
std::optional<MaterialParameterIssue> check_strain_rate(std::string_view law,
                                                        const MaterialParameters& p);
// The strain-rate law those parameters give (none without them).
std::optional<CowperSymonds> strain_rate_from(std::string_view law, const MaterialParameters& p);

}  // namespace partita::fem
