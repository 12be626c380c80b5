#include "partita/fem/shape_functions.hpp"

#include <array>

namespace partita::fem {
namespace {

// Reference coordinates of the Hex20 nodes (the first 8 are the Hex8 corners).
constexpr std::array<std::array<double, 3>, 20> kHexNodes = {{
    {-1, -1, -1}, {1, -1, -1}, {1, 1, -1},  {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1},
    {-1, 1, 1},   {0, -1, -1}, {1, 0, -1},  {0, 1, -1},  {-1, 0, -1}, {0, -1, 1}, {1, 0, 1},
    {0, 1, 1},    {-1, 0, 1},  {-1, -1, 0}, {1, -1, 0},  {1, 1, 0},   {-1, 1, 0},
}};
constexpr std::array<std::array<double, 3>, 10> kTetNodes = {{
    {0, 0, 0},
    {1, 0, 0},
    {0, 1, 0},
    {0, 0, 1},
    {0.5, 0, 0},
    {0.5, 0.5, 0},
    {0, 0.5, 0},
    {0, 0, 0.5},
    {0.5, 0, 0.5},
    {0, 0.5, 0.5},
}};
constexpr std::array<std::array<int, 2>, 6> kTetEdges = {
    {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};
constexpr std::array<std::array<double, 2>, 8> kQuadNodes = {{
    {-1, -1},
    {1, -1},
    {1, 1},
    {-1, 1},
    {0, -1},
    {1, 0},
    {0, 1},
    {-1, 0},
}};
constexpr std::array<std::array<int, 2>, 3> kTriEdges = {{{0, 1}, {1, 2}, {2, 0}}};

void hex8(const Vec3& x, ShapeVector& n, ShapeGradient& dn) {
  n.resize(8);
  dn.resize(8, 3);
  for (int a = 0; a < 8; ++a) {
    const double xa = kHexNodes[a][0], ya = kHexNodes[a][1], za = kHexNodes[a][2];
    const double p = 1 + x[0] * xa, q = 1 + x[1] * ya, r = 1 + x[2] * za;
    n[a] = 0.125 * p * q * r;
    dn(a, 0) = 0.125 * xa * q * r;
    dn(a, 1) = 0.125 * p * ya * r;
    dn(a, 2) = 0.125 * p * q * za;
  }
}

void hex20(const Vec3& x, ShapeVector& n, ShapeGradient& dn) {
  n.resize(20);
  dn.resize(20, 3);
  for (int a = 0; a < 20; ++a) {
    const double xa = kHexNodes[a][0], ya = kHexNodes[a][1], za = kHexNodes[a][2];
    const double p = 1 + x[0] * xa, q = 1 + x[1] * ya, r = 1 + x[2] * za;
    if (a < 8) {
      // N = 1/8 (1 + xi xi_a)(1 + eta eta_a)(1 + zeta zeta_a)(xi xi_a + eta eta_a + zeta zeta_a -
      // 2)
      const double s = x[0] * xa + x[1] * ya + x[2] * za - 2;
      n[a] = 0.125 * p * q * r * s;
      dn(a, 0) = 0.125 * xa * q * r * (s + p);
      dn(a, 1) = 0.125 * ya * p * r * (s + q);
      dn(a, 2) = 0.125 * za * p * q * (s + r);
    } else if (xa == 0) {  // N = 1/4 (1 - xi^2)(1 + eta eta_a)(1 + zeta zeta_a)
      const double b = 1 - x[0] * x[0];
      n[a] = 0.25 * b * q * r;
      dn(a, 0) = -0.5 * x[0] * q * r;
      dn(a, 1) = 0.25 * b * ya * r;
      dn(a, 2) = 0.25 * b * q * za;
    } else if (ya == 0) {
      const double b = 1 - x[1] * x[1];
      n[a] = 0.25 * p * b * r;
      dn(a, 0) = 0.25 * xa * b * r;
      dn(a, 1) = -0.5 * x[1] * p * r;
      dn(a, 2) = 0.25 * p * b * za;
    } else {
      const double b = 1 - x[2] * x[2];
      n[a] = 0.25 * p * q * b;
      dn(a, 0) = 0.25 * xa * q * b;
      dn(a, 1) = 0.25 * p * ya * b;
      dn(a, 2) = -0.5 * x[2] * p * q;
    }
  }
}

void tet(const Vec3& x, bool quadratic, ShapeVector& n, ShapeGradient& dn) {
  const std::array<double, 4> l = {1 - x[0] - x[1] - x[2], x[0], x[1], x[2]};
  // dL_i/dxi_j
  const std::array<std::array<double, 3>, 4> dl = {{{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  if (!quadratic) {
    n.resize(4);
    dn.resize(4, 3);
    for (int a = 0; a < 4; ++a) {
      n[a] = l[a];
      for (int j = 0; j < 3; ++j) dn(a, j) = dl[a][j];
    }
    return;
  }
  n.resize(10);
  dn.resize(10, 3);
  for (int a = 0; a < 4; ++a) {  // N = L (2 L - 1)
    n[a] = l[a] * (2 * l[a] - 1);
    for (int j = 0; j < 3; ++j) dn(a, j) = (4 * l[a] - 1) * dl[a][j];
  }
  for (int k = 0; k < 6; ++k) {  // N = 4 L_i L_j
    const int i = kTetEdges[k][0], j2 = kTetEdges[k][1];
    n[4 + k] = 4 * l[i] * l[j2];
    for (int j = 0; j < 3; ++j) dn(4 + k, j) = 4 * (dl[i][j] * l[j2] + l[i] * dl[j2][j]);
  }
}

}  // namespace

void shape_functions(ElementType type, const Vec3& xi, ShapeVector& n, ShapeGradient& dn) {
  switch (type) {
    case ElementType::Hex8:
      hex8(xi, n, dn);
      return;
    case ElementType::Hex20:
      hex20(xi, n, dn);
      return;
    case ElementType::Tet4:
      tet(xi, false, n, dn);
      return;
    case ElementType::Tet10:
      tet(xi, true, n, dn);
      return;
  }
}

void shape_functions(FaceType type, const Eigen::Vector2d& x, FaceShapeVector& n,
                     FaceShapeGradient& dn) {
  switch (type) {
    case FaceType::Quad4:
      n.resize(4);
      dn.resize(4, 2);
      for (int a = 0; a < 4; ++a) {
        const double xa = kQuadNodes[a][0], ya = kQuadNodes[a][1];
        n[a] = 0.25 * (1 + x[0] * xa) * (1 + x[1] * ya);
        dn(a, 0) = 0.25 * xa * (1 + x[1] * ya);
        dn(a, 1) = 0.25 * (1 + x[0] * xa) * ya;
      }
      return;
    case FaceType::Quad8:
      n.resize(8);
      dn.resize(8, 2);
      for (int a = 0; a < 8; ++a) {
        const double xa = kQuadNodes[a][0], ya = kQuadNodes[a][1];
        const double p = 1 + x[0] * xa, q = 1 + x[1] * ya;
        if (a < 4) {  // N = 1/4 (1 + xi xi_a)(1 + eta eta_a)(xi xi_a + eta eta_a - 1)
          const double s = x[0] * xa + x[1] * ya - 1;
          n[a] = 0.25 * p * q * s;
          dn(a, 0) = 0.25 * xa * q * (s + p);
          dn(a, 1) = 0.25 * ya * p * (s + q);
        } else if (xa == 0) {  // N = 1/2 (1 - xi^2)(1 + eta eta_a)
          n[a] = 0.5 * (1 - x[0] * x[0]) * q;
          dn(a, 0) = -x[0] * q;
          dn(a, 1) = 0.5 * (1 - x[0] * x[0]) * ya;
        } else {
          n[a] = 0.5 * p * (1 - x[1] * x[1]);
          dn(a, 0) = 0.5 * xa * (1 - x[1] * x[1]);
          dn(a, 1) = -x[1] * p;
        }
      }
      return;
    case FaceType::Tri3:
    case FaceType::Tri6: {
      const std::array<double, 3> l = {1 - x[0] - x[1], x[0], x[1]};
      const std::array<std::array<double, 2>, 3> dl = {{{-1, -1}, {1, 0}, {0, 1}}};
      if (type == FaceType::Tri3) {
        n.resize(3);
        dn.resize(3, 2);
        for (int a = 0; a < 3; ++a) {
          n[a] = l[a];
          dn(a, 0) = dl[a][0];
          dn(a, 1) = dl[a][1];
        }
        return;
      }
      n.resize(6);
      dn.resize(6, 2);
      for (int a = 0; a < 3; ++a) {
        n[a] = l[a] * (2 * l[a] - 1);
        for (int j = 0; j < 2; ++j) dn(a, j) = (4 * l[a] - 1) * dl[a][j];
      }
      for (int k = 0; k < 3; ++k) {
        const int i = kTriEdges[k][0], j2 = kTriEdges[k][1];
        n[3 + k] = 4 * l[i] * l[j2];
        for (int j = 0; j < 2; ++j) dn(3 + k, j) = 4 * (dl[i][j] * l[j2] + l[i] * dl[j2][j]);
      }
      return;
    }
  }
}

Vec3 reference_node(ElementType type, int i) {
  const auto k = static_cast<std::size_t>(i);
  if (type == ElementType::Hex8 || type == ElementType::Hex20) {
    return {kHexNodes[k][0], kHexNodes[k][1], kHexNodes[k][2]};
  }
  return {kTetNodes[k][0], kTetNodes[k][1], kTetNodes[k][2]};
}

}  // namespace partita::fem
