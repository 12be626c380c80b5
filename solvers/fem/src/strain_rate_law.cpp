#include "partita/fem/strain_rate_law.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

CowperSymonds::CowperSymonds(double d, double q) : d_(d), q_(q) {
  if (!(d > 0.0) || !std::isfinite(d)) {
    std::ostringstream msg;
    msg << "Cowper-Symonds: D must be a finite rate > 0 1/s, got " << d;
    throw Error(msg.str());
  }
  if (!(q > 0.0) || !std::isfinite(q)) {
    std::ostringstream msg;
    msg << "Cowper-Symonds: q must be a finite number > 0, got " << q;
    throw Error(msg.str());
  }
}

double CowperSymonds::factor(double rate) const {
  return 1.0 + std::pow(rate / d_, 1.0 / q_);
}

CowperSymonds::Return CowperSymonds::return_map(const HardeningCurve& hardening, double g,
                                                double trial_norm, double alpha_n,
                                                double dt) const {
  const double sqrt23 = std::sqrt(2.0 / 3.0), sqrt32 = std::sqrt(1.5);
  const double dtd = dt * d_;  // d alpha = dt D x^q
  const double sigma_n = hardening.yield_stress(alpha_n);
  const double f_tr = trial_norm - sqrt23 * sigma_n;
  // r(x) = |s_tr| - 2 G sqrt(3/2) d alpha - sqrt(2/3) sigma_y(alpha_n + d alpha) (1 + x),
  // decreasing in x; r(0) = f_tr > 0, r(hi) <= 0
  double lo = 0.0, hi = f_tr / (sqrt23 * sigma_n);
  double x = hi;
  const double tolerance = 1e-13 * hardening.initial_yield_stress();
  for (int it = 0;; ++it) {
    const double xq = std::pow(x, q_);
    const double dalpha = dtd * xq;
    const double alpha = alpha_n + dalpha;
    const double sigma = hardening.yield_stress(alpha);
    const double res = trial_norm - 2.0 * g * sqrt32 * dalpha - sqrt23 * sigma * (1.0 + x);
    if (std::abs(res) <= tolerance ||
        hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * hi) {
      Return r;
      r.dg = sqrt32 * dalpha;
      // H_eff = H (1 + x) + sigma_y x^(1 - q) / (q dt D)
      r.slope = hardening.slope(alpha) * (1.0 + x) + sigma * (x / xq) / (q_ * dtd);
      return r;
    }
    if (it == 200) {
      std::ostringstream msg;
      msg << "Cowper-Symonds: the viscoplastic return did not converge (residual " << res
          << " Pa after 200 iterations; trial stress " << trial_norm / (sqrt23 * sigma_n)
          << " times the yield stress, time step " << dt << " s)";
      throw Error(msg.str());
    }
    if (res > 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    // dr/dx = -(2 G sqrt(3/2) + sqrt(2/3) H (1 + x)) dt D q x^(q-1) - sqrt(2/3) sigma_y
    const double dalpha_dx = dtd * q_ * xq / x;
    const double slope =
        -(2.0 * g * sqrt32 + sqrt23 * hardening.slope(alpha) * (1.0 + x)) * dalpha_dx -
        sqrt23 * sigma;
    double next = x - res / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket: bisect
    x = next;
  }
}

std::vector<MaterialParameter> strain_rate_parameters() {
  return {MaterialParameter::number(
              "cowper_symonds_d", "1/s",
              "strain-rate hardening (Cowper-Symonds, of the equivalent plastic strain rate): "
              "sigma_y,dyn = sigma_y [1 + (rate / D)^(1/q)], D; mild steel 40.4 1/s (Jones, "
              "Structural Impact, ch. 8); give with cowper_symonds_q; dynamic analyses only")
              .positive()
              .typical(1.0, 1e5, "Cowper-Symonds D of metals (steels 40 to 3200, aluminium 6500)"),
          MaterialParameter::number("cowper_symonds_q", "",
                                    "Cowper-Symonds exponent q (mild steel 5); give with "
                                    "cowper_symonds_d")
              .positive()
              .typical(1.0, 12.0, "Cowper-Symonds q of metals (4 to 10)")};
}

std::optional<MaterialParameterIssue> check_strain_rate(std::string_view law,
                                                        const MaterialParameters& p) {
  const bool d = p.values().count("cowper_symonds_d") != 0;
  const bool q = p.values().count("cowper_symonds_q") != 0;
  if (d == q) return std::nullopt;
  const std::string given = d ? "cowper_symonds_d" : "cowper_symonds_q";
  const std::string missing = d ? "cowper_symonds_q" : "cowper_symonds_d";
  return MaterialParameterIssue{given,
                                -1,
                                "",
                                {},
                                std::string(law) + ": " + given + " without " + missing +
                                    ": the Cowper-Symonds law needs both D and q (mild steel: "
                                    "cowper_symonds_d: 40.4 1/s, cowper_symonds_q: 5)"};
}

std::optional<CowperSymonds> strain_rate_from(std::string_view law, const MaterialParameters& p) {
  if (auto issue = check_strain_rate(law, p)) throw Error(issue->message);
  if (p.values().count("cowper_symonds_d") == 0) return std::nullopt;
  return CowperSymonds(p.real("cowper_symonds_d"), p.real("cowper_symonds_q"));
}

}  // namespace partita::fem
