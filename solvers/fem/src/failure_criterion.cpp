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

namespace {

void require_hardening_exponent(const char* name, double n) {
  if (!(n > 0.0) || !(n < 1.0)) {
    throw Error(std::string("failure criterion '") + name +
                "': the hardening exponent n of sigma = K eps^n must be in (0, 1) (mild steel "
                "about 0.2), got " + std::to_string(n));
  }
}

void require_scaling(const char* name, double thickness, double n, double neck_strain) {
  if (!(thickness > 0.0) || !std::isfinite(thickness)) {
    throw Error(std::string("failure criterion '") + name +
                "': the plate thickness t of the size scaling must be > 0 [m], got " +
                std::to_string(thickness));
  }
  if (!(neck_strain >= n) || !std::isfinite(neck_strain)) {
    throw Error(std::string("failure criterion '") + name +
                "': the neck strain eps_n at fracture must be >= the hardening exponent n = " +
                std::to_string(n) + " (the uniform strain), got " + std::to_string(neck_strain));
  }
}

}  // namespace

FailureCriterion FailureCriterion::rtcl(double critical_strain, bool erosion) {
  if (!(critical_strain > 0.0) || !std::isfinite(critical_strain)) {
    throw Error("failure criterion 'rtcl': the critical strain eps_cr (the failure strain of "
                "uniaxial tension) must be > 0, got " + std::to_string(critical_strain));
  }
  FailureCriterion c;
  c.kind = Kind::Rtcl;
  c.strain = critical_strain;
  c.erosion = erosion;
  return c;
}

FailureCriterion FailureCriterion::rtcl_scaled(double thickness, double hardening_exponent,
                                               double neck_strain, bool erosion) {
  require_hardening_exponent("rtcl", hardening_exponent);
  require_scaling("rtcl", thickness, hardening_exponent, neck_strain);
  FailureCriterion c;
  c.kind = Kind::Rtcl;
  c.thickness = thickness;
  c.hardening_exponent = hardening_exponent;
  c.necking_strain = neck_strain;
  c.erosion = erosion;
  return c;
}

FailureCriterion FailureCriterion::bwh(double strength_coefficient, double hardening_exponent,
                                       double thickness, double neck_strain, bool erosion) {
  if (!(strength_coefficient > 0.0) || !std::isfinite(strength_coefficient)) {
    throw Error("failure criterion 'bwh': the strength coefficient K of sigma = K eps^n must "
                "be > 0 [Pa], got " + std::to_string(strength_coefficient));
  }
  require_hardening_exponent("bwh", hardening_exponent);
  if (thickness != 0.0 || neck_strain != 0.0)
    require_scaling("bwh", thickness, hardening_exponent, neck_strain);
  FailureCriterion c;
  c.kind = Kind::Bwh;
  c.strength_coefficient = strength_coefficient;
  c.hardening_exponent = hardening_exponent;
  c.thickness = thickness;
  c.necking_strain = neck_strain;
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
    case Kind::Rtcl:
    case Kind::Bwh:
      // eps_cr (RTCL) / eps_3 (BWH) = n + (eps_n - n) t / l_e when scaled
      if (thickness > 0.0)
        return hardening_exponent +
               (necking_strain - hardening_exponent) * thickness / element_length;
      return kind == Kind::Rtcl ? strain : hardening_exponent;
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

double rtcl_weight(double t) {
  if (!(t > -1.0 / 3.0)) return 0.0;
  if (t < 1.0 / 3.0) {
    // Cockcroft-Latham: sigma_1 / sigma_eq in plane stress at triaxiality T
    const double r = std::sqrt(12.0 - 27.0 * t * t);
    return 2.0 * (1.0 + t * r) / (3.0 * t + r);
  }
  return std::exp(1.5 * t - 0.5);  // Rice-Tracey, 1 at T = 1/3
}

double bwh_limit_stress(double alpha, double k, double n, double eps3) {
  if (!(alpha > -1.0)) return std::numeric_limits<double>::infinity();
  const double beta = (2.0 * alpha - 1.0) / (2.0 - alpha);
  const double two_over_root3 = 2.0 / std::sqrt(3.0);
  if (beta <= 0.0) {
    // Hill's local necking along the zero-extension direction: eps_1 + eps_2 = eps_3
    const double q = std::sqrt(beta * beta + beta + 1.0);
    return two_over_root3 * k * (1.0 + 0.5 * beta) / q *
           std::pow(two_over_root3 * eps3 * q / (1.0 + beta), n);
  }
  // Bressan-Williams: the through-thickness shear stress of plane strain
  const double r = beta / (2.0 + beta);
  return two_over_root3 * k * std::pow(two_over_root3 * eps3, n) / std::sqrt(1.0 - r * r);
}

double FailureCriterion::updated_damage(double damage, const Mat3& sigma, double d_eps_p,
                                        double critical, const Vec3& normal) const {
  if (!(d_eps_p > 0.0)) return damage;  // elastic steps do not damage
  if (kind == Kind::Rtcl) {
    const double mean = sigma.trace() / 3.0;
    const Mat3 dev = sigma - mean * Mat3::Identity();
    const double eq = std::sqrt(1.5 * dev.cwiseProduct(dev).sum());
    if (!(eq > 0.0)) return damage;
    return damage + rtcl_weight(mean / eq) * d_eps_p / critical;
  }
  if (kind != Kind::Bwh) return damage;
  // BWH is a forming-limit criterion of plane stress: the neck (or shear band) forms along the
  // strain path that J2 flow gives, and that path depends on the deviator alone. A solid element
  // of a plate carries a through-thickness stress sigma_33 where a web or a contact presses it;
  // the criterion reads the plane-stress state with the same deviator in the plate's plane,
  // (sigma_11 - sigma_33, sigma_22 - sigma_33, sigma_12), so that a pressure (or a tension)
  // through the thickness is not taken for in-plane tension. The transverse shears are left out,
  // as in a shell. Principal stresses of that in-plane state (plane normal `normal`):
  const Vec3 helper = std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = normal.cross(helper).normalized();
  const Vec3 e2 = normal.cross(e1);
  const double s33 = normal.dot(sigma * normal);
  const double s11 = e1.dot(sigma * e1) - s33, s22 = e2.dot(sigma * e2) - s33,
               s12 = e1.dot(sigma * e2);
  const double centre = 0.5 * (s11 + s22);
  const double radius = std::hypot(0.5 * (s11 - s22), s12);
  const double major = centre + radius, minor = centre - radius;
  if (!(major > 0.0)) return damage;
  const double limit =
      bwh_limit_stress(minor / major, strength_coefficient, hardening_exponent, critical);
  return std::max(damage, major / limit);
}

Vec3 failure_plate_normal(const Mesh& mesh, const Element& element) {
  if (element.type != ElementType::Hex8 && element.type != ElementType::Hex20) {
    throw Error("failure criterion 'bwh' is a plate criterion in the plate's plane: it needs "
                "hexahedral elements (their thinnest direction is the plate's normal); this "
                "part has tetrahedra");
  }
  const ElementCoordinates x = element_coordinates(mesh, element);
  ShapeVector n;
  ShapeGradient g;
  shape_functions(element.type, Vec3::Zero(), n, g);
  const Mat3 jac0 = x.transpose() * g;  // column J: dX/dxi_J
  Eigen::Index thin = 0;
  jac0.colwise().norm().minCoeff(&thin);
  return jac0.col(thin).normalized();
}

}  // namespace partita::fem
