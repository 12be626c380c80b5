#include "partita/fem/failure_criterion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/quadrature.hpp"

namespace partita::fem {

FailureCriterion FailureCriterion::constant(double strain, bool erosion) {
  if (!(strain > 0.0) || !std::isfinite(strain)) {
    throw Error("failure criterion: the failure strain must be > 0 (an equivalent plastic "
                "strain), got " + std::to_string(strain));
  }
  FailureCriterion c;
  c.kind = Kind::Constant;
  c.strain = strain;
  c.erosion = erosion;
  return c;
}

FailureCriterion FailureCriterion::germanischer_lloyd(double thickness, double uniform_strain,
                                                      double necking_strain, bool erosion) {
  if (!(thickness > 0.0) || !std::isfinite(thickness)) {
    throw Error("failure criterion 'gl': the plate thickness t must be > 0 [m], got " +
                std::to_string(thickness));
  }
  if (!(uniform_strain >= 0.0) || !(necking_strain >= 0.0) ||
      !(uniform_strain + necking_strain > 0.0)) {
    throw Error("failure criterion 'gl': the uniform strain eps_g and the necking strain eps_e "
                "must be >= 0 and not both 0 (mild steel: 0.056 and 0.54), got " +
                std::to_string(uniform_strain) + " and " + std::to_string(necking_strain));
  }
  FailureCriterion c;
  c.kind = Kind::GermanischerLloyd;
  c.uniform_strain = uniform_strain;
  c.necking_strain = necking_strain;
  c.thickness = thickness;
  c.erosion = erosion;
  return c;
}

double FailureCriterion::failure_strain(double element_length) const {
  switch (kind) {
    case Kind::Constant:
      return strain;
    case Kind::GermanischerLloyd:
      // eps_f = eps_g + eps_e t / l_e
      return uniform_strain + necking_strain * thickness / element_length;
    case Kind::None:
      break;
  }
  return std::numeric_limits<double>::infinity();
}

double failure_element_length(const Mesh& mesh, const Element& element) {
  const ElementCoordinates x = element_coordinates(mesh, element);
  ShapeVector n;
  ShapeGradient g;
  if (element.type == ElementType::Hex8 || element.type == ElementType::Hex20) {
    // a_J = 2 |dX/dxi_J| at the centre (xi in [-1, 1]); l_e = sqrt(a_1 a_2), the two largest
    shape_functions(element.type, Vec3::Zero(), n, g);
    const Mat3 jac0 = x.transpose() * g;  // column J: dX/dxi_J
    std::array<double, 3> a = {2.0 * jac0.col(0).norm(), 2.0 * jac0.col(1).norm(),
                               2.0 * jac0.col(2).norm()};
    std::sort(a.begin(), a.end());
    return std::sqrt(a[1] * a[2]);
  }
  // tetrahedra: the edge of the regular tetrahedron of the same volume, V = l^3 / (6 sqrt 2)
  double volume = 0.0;
  for (const auto& q : volume_rule(element.type, QuadratureUse::Mass))
    volume += physical_gradients(element.type, x, q.xi, n, g) * q.weight;
  return std::cbrt(6.0 * std::sqrt(2.0) * volume);
}

}  // namespace partita::fem
