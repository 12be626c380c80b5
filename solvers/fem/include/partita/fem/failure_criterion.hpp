#pragma once
#include "partita/fem/element.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem {

// The failure strain of a material (rupture): an element has failed when the mean of the
// equivalent plastic strain over its quadrature points (the committed history) reaches
// eps_f. The mean, not the largest point: the strain that the criterion's element length l_e
// refers to is the element's average, and a single point's value would make eps_f depend on
// the quadrature rule as well as on the size.
//   constant:            eps_f = strain
//   Germanischer Lloyd:  eps_f(l_e) = eps_g + eps_e t / l_e
// (GL's criterion for ship collision analysis, Scharrer, Zhang & Egge 2002, "Kollisions-
// berechnungen in schiffbaulichen Entwurfssystemen", GL report ESS 2002.183; as compared in
// Ehlers 2010, Marine Structures 23, 462-474, and Storheim, Amdahl & Martens 2015, Marine
// Structures 44, 254-287): eps_g the uniform strain (0.056 for mild steel), eps_e the necking
// strain (0.54), t the plate thickness, l_e the element length. On a hexahedral mesh of a plate
// t is given (a property of the part: with several elements through the plate no element knows
// it) and l_e is the element's in-plane size, sqrt(a_1 a_2) of its two largest extents a_J =
// 2 |dX/dxi_J| at the centre (the side of the square of the same in-plane area; the smallest
// extent is the one through the thickness); for a tetrahedron the edge of the regular
// tetrahedron of its volume, (6 sqrt(2) V)^(1/3).
// erosion: a failed element is removed from the model (explicit analyses only; see
// MaterialContribution and StructuralSolver).
struct FailureCriterion {
  enum class Kind { None, Constant, GermanischerLloyd };
  Kind kind = Kind::None;
  double strain = 0.0;          // constant: eps_f
  double uniform_strain = 0.0;  // GL: eps_g
  double necking_strain = 0.0;  // GL: eps_e
  double thickness = 0.0;       // GL: t [m]
  bool erosion = false;

  // Throw Error unless strain > 0 (constant) / eps_g >= 0, eps_e >= 0, t > 0 (GL).
  static FailureCriterion constant(double strain, bool erosion = false);
  static FailureCriterion germanischer_lloyd(double thickness, double uniform_strain = 0.056,
                                             double necking_strain = 0.54, bool erosion = false);
  bool active() const { return kind != Kind::None; }
  // eps_f of an element of length l_e [m] (infinite when inactive).
  double failure_strain(double element_length) const;
};

// l_e of an element as FailureCriterion defines it [m].
double failure_element_length(const Mesh& mesh, const Element& element);

}  // namespace partita::fem
