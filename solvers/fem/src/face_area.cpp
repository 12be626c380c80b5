#include "partita/fem/face_area.hpp"

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"

namespace partita::fem {

double face_area(const Mesh& mesh, const std::string& face) {
  const auto& elements = mesh.face(face);
  FaceShapeVector n;
  FaceShapeGradient dn;
  double total = 0.0;
  for (std::size_t s = 0; s < elements.size(); ++s) {
    const auto& se = elements[s];
    const int nn = node_count(se.type);
    Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxFaceNodes, 3> x(nn, 3);
    for (int a = 0; a < nn; ++a) x.row(a) = mesh.node(se.nodes[a]).transpose();
    for (const auto& q : face_rule(se.type)) {
      shape_functions(se.type, q.xi, n, dn);
      // dA = |dx/dxi x dx/deta| dxi deta
      const Vec3 t1 = x.transpose() * dn.col(0);
      const Vec3 t2 = x.transpose() * dn.col(1);
      const double da = t1.cross(t2).norm();
      if (!(da > 0.0))
        throw Error("face '" + face + "': degenerate surface element " + std::to_string(s));
      total += q.weight * da;
    }
  }
  return total;
}

double corner_area(const Mesh& mesh, const SurfaceElement& s) {
  const auto& x0 = mesh.node(s.nodes[0]);
  const auto& x1 = mesh.node(s.nodes[1]);
  const auto& x2 = mesh.node(s.nodes[2]);
  if (corner_count(s.type) == 3) return 0.5 * (x1 - x0).cross(x2 - x0).norm();
  const auto& x3 = mesh.node(s.nodes[3]);
  return 0.5 * (x2 - x0).cross(x3 - x1).norm();
}

double element_volume(const Mesh& mesh, const Element& e) {
  const ElementCoordinates x = element_coordinates(mesh, e);
  ShapeVector n;
  ShapeGradient g;
  double v = 0.0;
  for (const auto& q : volume_rule(e.type, QuadratureUse::Stiffness))
    v += physical_gradients(e.type, x, q.xi, n, g) * q.weight;
  return v;
}

}  // namespace partita::fem
