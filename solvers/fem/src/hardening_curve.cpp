#include "partita/fem/hardening_curve.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

HardeningCurve HardeningCurve::linear(double sigma0, double h) {
  if (!(sigma0 > 0.0)) {
    throw Error("j2-plasticity: the initial yield stress must be > 0 Pa, got " +
                std::to_string(sigma0));
  }
  if (!(h >= 0.0)) {
    throw Error("j2-plasticity: the hardening modulus must be >= 0 Pa (no softening), got " +
                std::to_string(h));
  }
  HardeningCurve c;
  c.linear_ = true;
  c.sigma0_ = sigma0;
  c.h_ = h;
  return c;
}

HardeningCurve HardeningCurve::tabulated(std::vector<std::pair<double, double>> points) {
  if (points.empty()) {
    throw Error("j2-plasticity: the hardening table is empty; give (plastic strain, stress) pairs");
  }
  if (points.front().first != 0.0) {
    throw Error("j2-plasticity: the hardening table must start at plastic strain 0, got " +
                std::to_string(points.front().first));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!(points[i].second > 0.0)) {
      std::ostringstream msg;
      msg << "j2-plasticity: hardening table row " << i << ": yield stress must be > 0 Pa, got "
          << points[i].second;
      throw Error(msg.str());
    }
    if (i > 0 && !(points[i].first > points[i - 1].first)) {
      std::ostringstream msg;
      msg << "j2-plasticity: hardening table row " << i << ": plastic strain " << points[i].first
          << " is not greater than the previous " << points[i - 1].first
          << " (the table must be strictly increasing in strain)";
      throw Error(msg.str());
    }
    if (i > 0 && points[i].second < points[i - 1].second) {
      std::ostringstream msg;
      msg << "j2-plasticity: hardening table row " << i << ": yield stress " << points[i].second
          << " is below the previous " << points[i - 1].second << " (softening is not supported)";
      throw Error(msg.str());
    }
  }
  HardeningCurve c;
  c.linear_ = false;
  c.points_ = std::move(points);
  c.sigma0_ = c.points_.front().second;
  return c;
}

double HardeningCurve::yield_stress(double alpha) const {
  if (linear_) return sigma0_ + h_ * alpha;
  // piecewise linear: sigma = sigma_i + (sigma_i+1 - sigma_i) (alpha - alpha_i) / (alpha_i+1 -
  // alpha_i) on [alpha_i, alpha_i+1], sigma_last beyond the table
  if (alpha >= points_.back().first) return points_.back().second;
  const auto it = std::upper_bound(points_.begin(), points_.end(), alpha,
                                   [](double a, const auto& p) { return a < p.first; });
  const auto& hi = *it;
  const auto& lo = *(it - 1);
  return lo.second + (hi.second - lo.second) * (alpha - lo.first) / (hi.first - lo.first);
}

double HardeningCurve::slope(double alpha) const {
  if (linear_) return h_;
  if (alpha >= points_.back().first) return 0.0;
  const auto it = std::upper_bound(points_.begin(), points_.end(), alpha,
                                   [](double a, const auto& p) { return a < p.first; });
  return (it->second - (it - 1)->second) / (it->first - (it - 1)->first);
}

double HardeningCurve::initial_yield_stress() const {
  return sigma0_;
}

double HardeningCurve::return_map_increment(double g, double trial_norm, double alpha_n) const {
  const double sqrt23 = std::sqrt(2.0 / 3.0);
  const double f_tr = trial_norm - sqrt23 * yield_stress(alpha_n);
  double dg = f_tr / (2.0 * g + 2.0 / 3.0 * slope(alpha_n));
  for (int it = 0;; ++it) {
    const double alpha = alpha_n + sqrt23 * dg;
    // r(dg) = |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha_n + sqrt(2/3) dg)
    const double res = trial_norm - 2.0 * g * dg - sqrt23 * yield_stress(alpha);
    if (std::abs(res) <= 1e-13 * sigma0_) return dg;
    if (it == 50) {
      std::ostringstream msg;
      msg << "j2-plasticity: the radial return did not converge (residual " << res
          << " Pa after 50 iterations; the trial stress was " << trial_norm / sigma0_
          << " times the yield stress: a strain increment that large in one step means an element "
             "crushed at once, e.g. by a contact that starts deep inside the structure, or a "
             "diverging step)";
      throw Error(msg.str());
    }
    dg += res / (2.0 * g + 2.0 / 3.0 * slope(alpha));
  }
}

std::vector<MaterialParameter> hardening_parameters() {
  // yield stresses of structural materials: soft polymers (about 1 MPa) to maraging and
  // high-strength steels (2-3 GPa)
  const auto yield_stress = [](std::string doc) {
    return MaterialParameter::number("yield_stress", "Pa", std::move(doc))
        .positive()
        .typical(1e5, 1e10, "yield stresses of solids (polymer foams to hardened steel)");
  };
  return {yield_stress("initial uniaxial yield stress (below E)"),
          MaterialParameter::number("hardening_modulus", "Pa",
                                    "linear isotropic hardening d sigma_y / d eps_p")
              .non_negative()
              .def(0.0),
          MaterialParameter::table(
              "hardening_table",
              "tabulated hardening instead of yield_stress and hardening_modulus (piecewise "
              "linear, flat beyond the last point)",
              "hardening_point", "a point of the hardening curve",
              {MaterialParameter::number("plastic_strain", "",
                                         "equivalent plastic strain (first point: 0)")
                   .non_negative(),
               yield_stress("uniaxial yield stress there")})};
}

std::optional<MaterialParameterIssue> check_hardening(std::string_view law,
                                                      const MaterialParameters& p) {
  const std::string name(law);
  const double e = p.real("youngs_modulus");
  // A yield stress at or above Young's modulus is a yield strain of 1 or more: a unit left out
  // (a bare number is in SI), not a material.
  const auto above_modulus = [&](double sigma_y) {
    std::ostringstream msg;
    msg << name << ": yield stress " << sigma_y << " Pa is not below Young's modulus " << e
        << " Pa: a yield strain sigma_y / E = " << std::setprecision(3) << sigma_y / e
        << ", where solids yield at 1e-4 to 1e-1 (a unit left out?)";
    return msg.str();
  };
  if (p.tables().count("hardening_table") != 0) {
    if (p.values().count("yield_stress") != 0)
      return MaterialParameterIssue{
          "yield_stress", -1, "", {"hardening_table"},
          name + ": give either yield_stress (and hardening_modulus) or hardening_table"};
    std::vector<std::pair<double, double>> points;
    const auto& rows = p.table("hardening_table");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      points.emplace_back(rows[i].at(0), rows[i].at(1));
      if (points.back().second >= e)
        return MaterialParameterIssue{"hardening_table", static_cast<int>(i), "yield_stress",
                                      {"youngs_modulus"}, above_modulus(points.back().second)};
    }
    try {
      HardeningCurve::tabulated(std::move(points));
    } catch (const Error& error) {
      return MaterialParameterIssue{"hardening_table", -1, "", {}, error.what()};
    }
    return std::nullopt;
  }
  if (p.values().count("yield_stress") == 0)
    return MaterialParameterIssue{
        "", -1, "", {},
        name + " needs 'yield_stress' (and optionally 'hardening_modulus') or 'hardening_table'"};
  if (p.real("yield_stress") >= e)
    return MaterialParameterIssue{"yield_stress", -1, "", {"youngs_modulus"},
                                  above_modulus(p.real("yield_stress"))};
  return std::nullopt;
}

HardeningCurve hardening_curve_from(std::string_view law, const MaterialParameters& p) {
  if (auto issue = check_hardening(law, p)) throw Error(issue->message);
  if (p.tables().count("hardening_table") != 0) {
    std::vector<std::pair<double, double>> points;
    for (const auto& row : p.table("hardening_table")) points.emplace_back(row.at(0), row.at(1));
    return HardeningCurve::tabulated(std::move(points));
  }
  const double h = p.values().count("hardening_modulus") != 0 ? p.real("hardening_modulus") : 0.0;
  return HardeningCurve::linear(p.real("yield_stress"), h);
}

}  // namespace partita::fem
