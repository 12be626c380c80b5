#include "partita/dem/fragment_pattern.hpp"

#include "partita/dem/error.hpp"

#include <cmath>

namespace partita::dem {

namespace {

// Radius q of a sphere in the gap along the cube diagonal u = (1,1,1)/sqrt(3), touching the unit
// parent (centre at s u, s = 1 - q) and the octahedral spheres of radius rho at distance d on the
// axes: |s u - d e_x| = rho + q, i.e. s^2 - 2 s d/sqrt(3) + d^2 = (rho + q)^2 (bisection: the
// left side minus the right decreases in q).
double gap_radius(double rho, double d) {
  auto g = [&](double q) {
    const double s = 1.0 - q;
    return s * s - 2.0 * s * d / std::sqrt(3.0) + d * d - (rho + q) * (rho + q);
  };
  double lo = 0.0, hi = 1.0 - d;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

FragmentPattern::FragmentPattern(Kind kind) : kind_(kind) {
  const double c = 1.0 / std::sqrt(3.0);
  if (kind == Kind::equal_4) {
    const double rho = 1.0 / (1.0 + std::sqrt(1.5));
    const double d = 1.0 - rho;
    for (const Eigen::Vector3d& u : {Eigen::Vector3d(c, c, c), Eigen::Vector3d(c, -c, -c),
                                     Eigen::Vector3d(-c, c, -c), Eigen::Vector3d(-c, -c, c)}) {
      centre_.push_back(d * u);
      radius_.push_back(rho);
    }
    return;
  }
  const double rho = 1.0 / (1.0 + std::sqrt(2.0));
  const double d = 1.0 - rho;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      x[axis] = sign * d;
      centre_.push_back(x);
      radius_.push_back(rho);
    }
  if (kind == Kind::equal_6) return;
  const double q = gap_radius(rho, d);
  for (double sx : {1.0, -1.0})
    for (double sy : {1.0, -1.0})
      for (double sz : {1.0, -1.0}) {
        centre_.push_back((1.0 - q) * c * Eigen::Vector3d(sx, sy, sz));
        radius_.push_back(q);
      }
}

std::vector<std::string> FragmentPattern::names() {
  return {"equal-4", "equal-6", "apollonian-14"};
}

std::string FragmentPattern::name() const {
  switch (kind_) {
    case Kind::equal_4:
      return "equal-4";
    case Kind::equal_6:
      return "equal-6";
    case Kind::apollonian_14:
      return "apollonian-14";
  }
  return "";
}

FragmentPattern FragmentPattern::named(const std::string& name) {
  if (name == "equal-4") return FragmentPattern(Kind::equal_4);
  if (name == "equal-6") return FragmentPattern(Kind::equal_6);
  if (name == "apollonian-14") return FragmentPattern(Kind::apollonian_14);
  throw Error("unknown fragment pattern '" + name + "'; known: equal-4, equal-6, apollonian-14");
}

double FragmentPattern::volume_fraction() const {
  double v = 0.0;
  for (double r : radius_) v += r * r * r;
  return v;
}

}  // namespace partita::dem
