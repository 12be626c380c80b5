#include "partita/fem/quadrature.hpp"

#include <array>
#include <cmath>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

struct Gauss1d {
  std::vector<double> x, w;
};

Gauss1d gauss_legendre(int n) {
  switch (n) {
    case 1:
      return {{0.0}, {2.0}};
    case 2: {
      const double a = 1.0 / std::sqrt(3.0);
      return {{-a, a}, {1.0, 1.0}};
    }
    case 3: {
      const double a = std::sqrt(0.6);
      return {{-a, 0.0, a}, {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0}};
    }
    case 6: {
      constexpr std::array<double, 3> x = {0.2386191860831969, 0.6612093864662645,
                                           0.9324695142031521};
      constexpr std::array<double, 3> w = {0.4679139345726910, 0.3607615730481386,
                                           0.1713244923791704};
      return {{-x[2], -x[1], -x[0], x[0], x[1], x[2]}, {w[2], w[1], w[0], w[0], w[1], w[2]}};
    }
    default: {  // 4 points
      const double a = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(1.2));
      const double b = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(1.2));
      const double wa = (18.0 + std::sqrt(30.0)) / 36.0;
      const double wb = (18.0 - std::sqrt(30.0)) / 36.0;
      return {{-b, -a, a, b}, {wb, wa, wa, wb}};
    }
  }
}

std::vector<VolumeRulePoint> hex_rule(int n) {
  const Gauss1d g = gauss_legendre(n);
  std::vector<VolumeRulePoint> r;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        r.push_back({Vec3(g.x[i], g.x[j], g.x[k]), g.w[i] * g.w[j] * g.w[k]});
      }
    }
  }
  return r;
}

// Tetrahedron by the collapsed (Duffy) map of [0,1]^3: x = u, y = v (1-u), z = w (1-u)(1-v),
// dV = (1-u)^2 (1-v) du dv dw, with n-point Gauss-Legendre in u, v, w.
std::vector<VolumeRulePoint> collapsed_tet_rule(int n) {
  const Gauss1d g = gauss_legendre(n);
  std::vector<VolumeRulePoint> r;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const double u = 0.5 * (g.x[i] + 1), v = 0.5 * (g.x[j] + 1), w = 0.5 * (g.x[k] + 1);
        const double weight = 0.125 * g.w[i] * g.w[j] * g.w[k] * (1 - u) * (1 - u) * (1 - v);
        r.push_back({Vec3(u, v * (1 - u), w * (1 - u) * (1 - v)), weight});
      }
    }
  }
  return r;
}

std::vector<VolumeRulePoint> tet_rule_1() {
  return {{Vec3(0.25, 0.25, 0.25), 1.0 / 6.0}};
}

std::vector<VolumeRulePoint> tet_rule_4() {
  const double a = 0.5854101966249685, b = 0.1381966011250105;
  const double w = 1.0 / 24.0;
  return {{Vec3(b, b, b), w}, {Vec3(a, b, b), w}, {Vec3(b, a, b), w}, {Vec3(b, b, a), w}};
}

std::vector<FaceRulePoint> quad_rule(int n) {
  const Gauss1d g = gauss_legendre(n);
  std::vector<FaceRulePoint> r;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) r.push_back({Eigen::Vector2d(g.x[i], g.x[j]), g.w[i] * g.w[j]});
  }
  return r;
}

std::vector<FaceRulePoint> tri_rule_3() {
  const double w = 1.0 / 6.0;
  return {{Eigen::Vector2d(1.0 / 6.0, 1.0 / 6.0), w},
          {Eigen::Vector2d(2.0 / 3.0, 1.0 / 6.0), w},
          {Eigen::Vector2d(1.0 / 6.0, 2.0 / 3.0), w}};
}

// Dunavant (1985), degree 4, 6 points.
std::vector<FaceRulePoint> tri_rule_6() {
  const double a1 = 0.445948490915965, w1 = 0.5 * 0.223381589678011;
  const double a2 = 0.091576213509771, w2 = 0.5 * 0.109951743655322;
  return {{Eigen::Vector2d(a1, a1), w1},         {Eigen::Vector2d(1 - 2 * a1, a1), w1},
          {Eigen::Vector2d(a1, 1 - 2 * a1), w1}, {Eigen::Vector2d(a2, a2), w2},
          {Eigen::Vector2d(1 - 2 * a2, a2), w2}, {Eigen::Vector2d(a2, 1 - 2 * a2), w2}};
}

}  // namespace

const std::vector<VolumeRulePoint>& layered_hex_rule(int thin) {
  auto make = [](int t) {
    const Gauss1d across = gauss_legendre(2), through = gauss_legendre(6);
    const int a = (t + 1) % 3, b = (t + 2) % 3;
    std::vector<VolumeRulePoint> r;
    for (std::size_t k = 0; k < through.x.size(); ++k) {
      for (std::size_t j = 0; j < across.x.size(); ++j) {
        for (std::size_t i = 0; i < across.x.size(); ++i) {
          Vec3 xi;
          xi[a] = across.x[i];
          xi[b] = across.x[j];
          xi[t] = through.x[k];
          r.push_back({xi, across.w[i] * across.w[j] * through.w[k]});
        }
      }
    }
    return r;
  };
  static const std::array<std::vector<VolumeRulePoint>, 3> rules = {make(0), make(1), make(2)};
  return rules.at(static_cast<std::size_t>(thin));
}

const std::vector<VolumeRulePoint>& thickness_line_rule(int thin, int points) {
  auto make = [](int t, int n) {
    const Gauss1d through = gauss_legendre(n);
    std::vector<VolumeRulePoint> r;
    for (std::size_t k = 0; k < through.x.size(); ++k) {
      Vec3 xi = Vec3::Zero();
      xi[t] = through.x[k];
      r.push_back({xi, 4.0 * through.w[k]});
    }
    return r;
  };
  static const std::array<std::vector<VolumeRulePoint>, 6> rules = {
      make(0, 2), make(1, 2), make(2, 2), make(0, 6), make(1, 6), make(2, 6)};
  if (thin < 0 || thin > 2 || (points != 2 && points != 6))
    throw Error("thickness_line_rule: direction 0, 1 or 2 and 2 or 6 points");
  return rules[static_cast<std::size_t>(thin + (points == 6 ? 3 : 0))];
}

const std::vector<VolumeRulePoint>& volume_rule(ElementType type, QuadratureUse use) {
  static const std::vector<VolumeRulePoint> hex2 = hex_rule(2);
  static const std::vector<VolumeRulePoint> hex3 = hex_rule(3);
  static const std::vector<VolumeRulePoint> tet1 = tet_rule_1();
  static const std::vector<VolumeRulePoint> tet4 = tet_rule_4();
  static const std::vector<VolumeRulePoint> tet64 = collapsed_tet_rule(4);
  switch (type) {
    case ElementType::Hex8:
      return hex2;
    case ElementType::Hex20:
      return hex3;
    case ElementType::Tet4:
      return use == QuadratureUse::Stiffness ? tet1 : tet4;
    case ElementType::Tet10:
      return use == QuadratureUse::Stiffness ? tet4 : tet64;
  }
  return hex2;
}

const std::vector<FaceRulePoint>& face_rule(FaceType type) {
  static const std::vector<FaceRulePoint> quad2 = quad_rule(2);
  static const std::vector<FaceRulePoint> quad3 = quad_rule(3);
  static const std::vector<FaceRulePoint> tri3 = tri_rule_3();
  static const std::vector<FaceRulePoint> tri6 = tri_rule_6();
  switch (type) {
    case FaceType::Quad4:
      return quad2;
    case FaceType::Quad8:
      return quad3;
    case FaceType::Tri3:
      return tri3;
    case FaceType::Tri6:
      return tri6;
  }
  return quad2;
}

}  // namespace partita::fem
