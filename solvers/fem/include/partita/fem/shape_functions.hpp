#pragma once
#include "partita/fem/element_type.hpp"
#include "partita/fem/face_type.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// Shape function values N (n) and reference derivatives dN (n x 3: d/dxi, d/deta, d/dzeta).
using ShapeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1>;
using ShapeGradient = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxElementNodes, 3>;
using FaceShapeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxFaceNodes, 1>;
using FaceShapeGradient = Eigen::Matrix<double, Eigen::Dynamic, 2, 0, kMaxFaceNodes, 2>;

// Reference elements: hexahedra on [-1,1]^3, tetrahedra 0 <= xi, eta, zeta, xi+eta+zeta <= 1
// (L0 = 1-xi-eta-zeta, L1 = xi, L2 = eta, L3 = zeta); quadrilaterals on [-1,1]^2, triangles
// 0 <= xi, eta, xi+eta <= 1.
void shape_functions(ElementType type, const Vec3& xi, ShapeVector& n, ShapeGradient& dn);
void shape_functions(FaceType type, const Eigen::Vector2d& xi, FaceShapeVector& n,
                     FaceShapeGradient& dn);

// Reference coordinates of local node i.
Vec3 reference_node(ElementType type, int i);

}  // namespace partita::fem
