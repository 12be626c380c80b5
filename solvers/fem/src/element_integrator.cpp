#include "partita/fem/element_integrator.hpp"

#include <Eigen/Dense>
#include <sstream>

#include "partita/fem/error.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"

namespace partita::fem {
namespace {

using StrainMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, kMaxElementDofs>;

// B (6 x 3n): strain = B u_e, rows xx yy zz xy yz zx (engineering shears).
void strain_matrix(const ShapeGradient& g, StrainMatrix& b) {
  const auto n = g.rows();
  b.setZero(6, 3 * n);
  for (Eigen::Index a = 0; a < n; ++a) {
    const double gx = g(a, 0), gy = g(a, 1), gz = g(a, 2);
    const Eigen::Index c = 3 * a;
    b(0, c) = gx;
    b(1, c + 1) = gy;
    b(2, c + 2) = gz;
    b(3, c) = gy;
    b(3, c + 1) = gx;
    b(4, c + 1) = gz;
    b(4, c + 2) = gy;
    b(5, c) = gz;
    b(5, c + 2) = gx;
  }
}

// out += B(ga)^T D B(gb): the 3 na x 3 nb block of B^T D B between the points (nodes, or the
// incompatible modes) with gradient rows ga (na x 3) and gb (nb x 3), written out from the nine
// non-zeros of each point's B (as strain_matrix() places them). First C = B(ga)^T D (3 na x 6),
// then out's columns, each a combination of three columns of C: contiguous, vectorised, and no
// packing as a general matrix product of these small sizes does (the scale case's 105,800 Hex8
// with incompatible modes spent most of their element time there).
template <class GA, class GB, class Out>
void add_btdb(const GA& ga, const GB& gb, const Matrix6& d, Out&& out) {
  const Eigen::Index na = ga.rows(), nb = gb.rows();
  Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxElementDofs, 6> c(3 * na, 6);
  for (Eigen::Index a = 0; a < na; ++a) {
    const double gx = ga(a, 0), gy = ga(a, 1), gz = ga(a, 2);
    for (int r = 0; r < 6; ++r) {  // (scalar: rows of a column-major block are strided)
      c(3 * a, r) = gx * d(0, r) + gy * d(3, r) + gz * d(5, r);
      c(3 * a + 1, r) = gy * d(1, r) + gx * d(3, r) + gz * d(4, r);
      c(3 * a + 2, r) = gz * d(2, r) + gy * d(4, r) + gx * d(5, r);
    }
  }
  for (Eigen::Index b = 0; b < nb; ++b) {
    const double gx = gb(b, 0), gy = gb(b, 1), gz = gb(b, 2);
    out.col(3 * b) += gx * c.col(0) + gy * c.col(3) + gz * c.col(5);
    out.col(3 * b + 1) += gy * c.col(1) + gx * c.col(3) + gz * c.col(4);
    out.col(3 * b + 2) += gz * c.col(2) + gy * c.col(4) + gx * c.col(5);
  }
}

}  // namespace

double physical_gradients(ElementType type, const ElementCoordinates& x, const Vec3& xi,
                          ShapeVector& n, ShapeGradient& dndx) {
  ShapeGradient dn;
  shape_functions(type, xi, n, dn);
  const Mat3 j = dn.transpose() * x;
  const double det = j.determinant();
  if (!(det > 0.0)) {
    std::ostringstream msg;
    msg << to_string(type) << " element with non-positive Jacobian determinant " << det
        << " at reference point (" << xi.transpose()
        << "): the element is inverted or degenerate (check node order and positions; first node "
           "at ("
        << x.row(0) << "))";
    throw Error(msg.str());
  }
  dndx = dn * j.inverse().transpose();
  return det;
}

ElementCoordinates element_coordinates(const Mesh& mesh, const Element& e) {
  const int n = node_count(e.type);
  ElementCoordinates x(n, 3);
  for (int a = 0; a < n; ++a) x.row(a) = mesh.node(e.nodes[a]).transpose();
  return x;
}

void ElementIntegrator::stiffness(ElementType type, const ElementCoordinates& x, const Matrix6& d,
                                  ElementMatrix& ke) const {
  if (type == ElementType::Hex8 && hex8_ == Hex8Formulation::IncompatibleModes) {
    hex8_incompatible(x, d, ke, nullptr, nullptr);
    return;
  }
  const int ndof = 3 * node_count(type);
  ke.setZero(ndof, ndof);
  ShapeVector n;
  ShapeGradient g;
  // K_e = sum_q B^T D B det J w
  for (const auto& q : volume_rule(type, QuadratureUse::Stiffness)) {
    const double det = physical_gradients(type, x, q.xi, n, g);
    add_btdb(g, g, d * (det * q.weight), ke);
  }
}

void ElementIntegrator::hex8_incompatible(const ElementCoordinates& x, const Matrix6& d,
                                          ElementMatrix& ke, const ElementVector* ue,
                                          ElementStresses* s) const {
  // Compatible part u = N u_e, incompatible part u_a = sum_k P_k alpha_k with
  // P = (1 - xi^2, 1 - eta^2, 1 - zeta^2) per component (9 internal dofs). Their gradients use
  // the centre Jacobian J0 (Taylor et al. 1976): dP/dx = det J0 / det J J0^-1 dP/dxi.
  ShapeVector n;
  ShapeGradient dn0;
  shape_functions(ElementType::Hex8, Vec3::Zero(), n, dn0);
  const Mat3 j0 = dn0.transpose() * x;
  const double det0 = j0.determinant();
  if (!(det0 > 0.0)) {
    throw Error(
        "hex8 element with non-positive Jacobian determinant at its centre: inverted or "
        "degenerate");
  }
  const Mat3 j0inv = j0.inverse();

  Eigen::Matrix<double, 24, 24> kuu = Eigen::Matrix<double, 24, 24>::Zero();
  Eigen::Matrix<double, 24, 9> kua = Eigen::Matrix<double, 24, 9>::Zero();
  Eigen::Matrix<double, 9, 9> kaa = Eigen::Matrix<double, 9, 9>::Zero();
  ShapeGradient g;
  // the incompatible modes' gradient rows (one per mode, as the nodes' rows of g)
  Eigen::Matrix<double, 3, 3> gp;
  auto incompatible_gradients = [&](const Vec3& xi, double det) {
    for (int k = 0; k < 3; ++k) {
      Vec3 dpdxi = Vec3::Zero();
      dpdxi[k] = -2.0 * xi[k];
      gp.row(k) = (det0 / det) * (j0inv * dpdxi).transpose();
    }
  };
  // K_uu = sum B^T D B, K_ua = sum B^T D G, K_aa = sum G^T D G  (det J w)
  for (const auto& q : volume_rule(ElementType::Hex8, QuadratureUse::Stiffness)) {
    const double det = physical_gradients(ElementType::Hex8, x, q.xi, n, g);
    incompatible_gradients(q.xi, det);
    const Matrix6 dw = d * (det * q.weight);
    if (s == nullptr) add_btdb(g, g, dw, kuu);  // (stresses need K_ua, K_aa only)
    add_btdb(g, gp, dw, kua);
    add_btdb(gp, gp, dw, kaa);
  }
  const Eigen::LDLT<Eigen::Matrix<double, 9, 9>> kaa_ldlt(kaa);
  // Static condensation: K = K_uu - K_ua K_aa^-1 K_au; alpha = -K_aa^-1 K_au u_e.
  const Eigen::Matrix<double, 9, 24> r = kaa_ldlt.solve(kua.transpose());
  if (s == nullptr) {
    ke = kuu;
    ke.noalias() -= kua.lazyProduct(r);
    return;
  }
  const Eigen::Matrix<double, 9, 1> alpha = -r * (*ue);
  s->resize(8, 6);
  StrainMatrix b, ba;
  for (int a = 0; a < 8; ++a) {
    const Vec3 xi = reference_node(ElementType::Hex8, a);
    const double det = physical_gradients(ElementType::Hex8, x, xi, n, g);
    strain_matrix(g, b);
    incompatible_gradients(xi, det);
    strain_matrix(gp, ba);
    s->row(a) = (d * (b * (*ue) + ba * alpha)).transpose();
  }
}

void ElementIntegrator::consistent_mass(ElementType type, const ElementCoordinates& x, double rho,
                                        ElementMatrix& me) const {
  const int nn = node_count(type);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxElementNodes, kMaxElementNodes> m;
  m.setZero(nn, nn);
  ShapeVector n;
  ShapeGradient g;
  // M_ab = sum_q rho N_a N_b det J w
  for (const auto& q : volume_rule(type, QuadratureUse::Mass)) {
    const double det = physical_gradients(type, x, q.xi, n, g);
    m.noalias() += n * n.transpose() * (rho * det * q.weight);
  }
  me.setZero(3 * nn, 3 * nn);
  for (int a = 0; a < nn; ++a) {
    for (int b2 = 0; b2 < nn; ++b2) {
      for (int c = 0; c < 3; ++c) me(3 * a + c, 3 * b2 + c) = m(a, b2);
    }
  }
}

void ElementIntegrator::lumped_mass(
    ElementType type, const ElementCoordinates& x, double rho,
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1>& m) const {
  const int nn = node_count(type);
  m.setZero(nn);
  ShapeVector n;
  ShapeGradient g;
  double total = 0.0;
  // HRZ: m_a = (sum_q rho N_a^2 det J w) * (rho V) / sum_b (sum_q rho N_b^2 det J w)
  for (const auto& q : volume_rule(type, QuadratureUse::Mass)) {
    const double det = physical_gradients(type, x, q.xi, n, g);
    m += n.cwiseAbs2() * (rho * det * q.weight);
    total += rho * det * q.weight;
  }
  m *= total / m.sum();
}

void ElementIntegrator::body_force(ElementType type, const ElementCoordinates& x, const Vec3& bf,
                                   ElementVector& fe) const {
  const int nn = node_count(type);
  fe.setZero(3 * nn);
  ShapeVector n;
  ShapeGradient g;
  // f_a = sum_q N_a b det J w
  for (const auto& q : volume_rule(type, QuadratureUse::Mass)) {
    const double det = physical_gradients(type, x, q.xi, n, g);
    for (int a = 0; a < nn; ++a) fe.segment<3>(3 * a) += n[a] * det * q.weight * bf;
  }
}

double ElementIntegrator::volume(ElementType type, const ElementCoordinates& x) const {
  ShapeVector n;
  ShapeGradient g;
  double v = 0.0;
  for (const auto& q : volume_rule(type, QuadratureUse::Mass)) {
    v += physical_gradients(type, x, q.xi, n, g) * q.weight;
  }
  return v;
}

void ElementIntegrator::stresses_at_nodes(ElementType type, const ElementCoordinates& x,
                                          const Matrix6& d, const ElementVector& ue,
                                          ElementStresses& s) const {
  if (type == ElementType::Hex8 && hex8_ == Hex8Formulation::IncompatibleModes) {
    ElementMatrix unused;
    hex8_incompatible(x, d, unused, &ue, &s);
    return;
  }
  const int nn = node_count(type);
  s.resize(nn, 6);
  ShapeVector n;
  ShapeGradient g;
  StrainMatrix b;
  // sigma = D B(xi_a) u_e at each node a
  for (int a = 0; a < nn; ++a) {
    physical_gradients(type, x, reference_node(type, a), n, g);
    strain_matrix(g, b);
    s.row(a) = (d * (b * ue)).transpose();
  }
}

}  // namespace partita::fem
