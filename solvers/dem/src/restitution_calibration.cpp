#include "partita/dem/restitution_calibration.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace partita::dem {

namespace {

void check_restitution(double e) {
  if (!(e > 0.0 && e <= 1.0)) {
    std::ostringstream msg;
    msg << "coefficient of restitution must be in (0, 1], got " << e;
    throw Error(msg.str());
  }
}

}  // namespace

double RestitutionCalibration::restitution(double zeta, bool no_tension) {
  if (zeta <= 0.0) return 1.0;
  const double c = 2.0 * std::sqrt(1.5) * zeta;
  // Scaled equation x'' = -(x^(3/2) + c x^(1/4) x'), force clamped at >= 0 when no_tension.
  auto accel = [&](double x, double v) {
    const double xp = std::max(x, 0.0);
    const double sx = std::sqrt(xp);
    double f = xp * sx + c * std::sqrt(sx) * v;
    if (no_tension) f = std::max(f, 0.0);
    return -f;
  };
  // Undamped contact lasts about 3.2 time units; h = 5e-4 resolves e to ~1e-7.
  const double h = 5.0e-4;
  double x = 0.0;
  double v = 1.0;
  for (long n = 0; n < 40'000'000; ++n) {
    // classical RK4 on (x, v)
    const double k1x = v, k1v = accel(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = accel(x + h * k3x, v + h * k3v);
    const double xn = x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    const double vn = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    if (xn <= 0.0 && vn < 0.0 && n > 0) {
      // linear interpolation of the velocity at the crossing x = 0
      const double s = x / (x - xn);
      return -(v + s * (vn - v));
    }
    if (vn >= 0.0 && xn > 0.0 && v < 0.0) return 0.0;  // came to rest inside the contact
    x = xn;
    v = vn;
  }
  return 0.0;
}

double RestitutionCalibration::damping_ratio(double e, bool no_tension) {
  check_restitution(e);
  if (e == 1.0) return 0.0;
  // e(zeta) decreases monotonically: bracket, then bisect.
  double lo = 0.0;
  double hi = 1.0;
  while (restitution(hi, no_tension) > e) {
    lo = hi;
    hi *= 2.0;
    if (hi > 1.0e3) {
      std::ostringstream msg;
      msg << "coefficient of restitution " << e
          << " is below what the calibrated Hertz damping can realise; use e >= 0.01";
      throw Error(msg.str());
    }
  }
  for (int it = 0; it < 60 && hi - lo > 1.0e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (restitution(mid, no_tension) > e)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

double RestitutionCalibration::time_step_fraction(double e) {
  check_restitution(e);
  // measured worst relative error over v = 0.01..3 m/s, pairs and walls (see the header)
  if (e < 0.15) return 0.02;
  if (e < 0.2) return 0.05;
  if (e < 0.9) return 0.1;
  return 0.2;
}

double RestitutionCalibration::liggghts_damping_ratio(double e) {
  check_restitution(e);
  const double le = std::log(e);
  const double beta = le / std::sqrt(le * le + std::numbers::pi * std::numbers::pi);
  return -std::sqrt(5.0 / 6.0) * beta;
}

}  // namespace partita::dem
