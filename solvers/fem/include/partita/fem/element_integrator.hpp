#pragma once
#include "partita/fem/element_type.hpp"
#include "partita/fem/face_type.hpp"
#include "partita/fem/hex8_formulation.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/shape_functions.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

using ElementCoordinates = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxElementNodes, 3>;
using ElementMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxElementDofs, kMaxElementDofs>;
using ElementVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementDofs, 1>;
using ElementStresses = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxElementNodes, 6>;

// Node coordinates (n x 3) of element e in its node order.
ElementCoordinates element_coordinates(const Mesh& mesh, const Element& e);
// Shape functions n and physical gradients dN/dx (n x 3) at reference point xi; returns det J.
// J_ij = dx_j/dxi_i = sum_a dN_a/dxi_i x_aj;  dN_a/dx = J^-1 dN_a/dxi. Throws Error when
// det J <= 0 (inverted or degenerate element).
double physical_gradients(ElementType type, const ElementCoordinates& x, const Vec3& xi,
                          ShapeVector& n, ShapeGradient& dndx);

// Element matrices of one element at a time (dof order: node-major, x y z per node).
// x holds the element's node coordinates (n x 3) in the element's node order.
// Throws Error when the Jacobian determinant is not positive at a quadrature point.
class ElementIntegrator {
 public:
  explicit ElementIntegrator(Hex8Formulation hex8 = Hex8Formulation::IncompatibleModes)
      : hex8_(hex8) {}

  // K_e = sum_q B^T D B det J w (Hex8 incompatible modes: condensed K_uu - K_ua K_aa^-1 K_au).
  void stiffness(ElementType type, const ElementCoordinates& x, const Matrix6& d,
                 ElementMatrix& ke) const;
  // M_e = sum_q rho N^T N det J w (consistent).
  void consistent_mass(ElementType type, const ElementCoordinates& x, double rho,
                       ElementMatrix& me) const;
  // Diagonal HRZ lumped mass (Hinton, Rock & Zienkiewicz 1976): m_a = M_aa rho V / sum_b M_bb,
  // positive for all four element types. Returns the n diagonal entries per node.
  void lumped_mass(ElementType type, const ElementCoordinates& x, double rho,
                   Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1>& m) const;
  // f_e = sum_q N^T b det J w for a body force density b [N/m^3].
  void body_force(ElementType type, const ElementCoordinates& x, const Vec3& b,
                  ElementVector& fe) const;
  // Volume sum_q det J w.
  double volume(ElementType type, const ElementCoordinates& x) const;
  // Stresses D (B u_e [+ G alpha]) evaluated at each element node (n x 6, Voigt).
  void stresses_at_nodes(ElementType type, const ElementCoordinates& x, const Matrix6& d,
                         const ElementVector& ue, ElementStresses& s) const;

 private:
  void hex8_incompatible(const ElementCoordinates& x, const Matrix6& d, ElementMatrix& ke,
                         const ElementVector* ue, ElementStresses* s) const;
  Hex8Formulation hex8_;
};

}  // namespace partita::fem
