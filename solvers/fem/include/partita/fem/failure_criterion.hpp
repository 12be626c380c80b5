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
//
// Two damage criteria of ship-collision analysis evaluate the stress state of every quadrature
// point over time; a point carries a damage D (0 at rest, committed history: restarts keep it)
// and an element has failed when the mean of D over its points reaches 1 (the mean, as above).
//   RTCL (Rice-Tracey / Cockcroft-Latham; Toernqvist 2003, "Design of crashworthy ship
//   structures", PhD thesis, DTU; compared in Storheim, Amdahl & Martens 2015): damage by the
//   stress triaxiality T = sigma_m / sigma_eq (sigma_m = tr(sigma) / 3, sigma_eq von Mises)
//   along the plastic strain path, accumulated at each step's commit:
//     D = (1 / eps_cr) int f(T) d eps_p,
//     f(T) = 0                                                       T <= -1/3
//     f(T) = 2 (1 + T sqrt(12 - 27 T^2)) / (3 T + sqrt(12 - 27 T^2))  -1/3 < T < 1/3
//                                        (Cockcroft-Latham: the major principal stress's work)
//     f(T) = exp(3/2 T - 1/2)                                        T >= 1/3 (Rice-Tracey)
//   both branches 1 at T = 1/3 (Toernqvist writes the Rice-Tracey branch exp(3/2 T) / 1.65,
//   1.65 ~ e^(1/2); here e^(1/2) exactly, so that f is continuous), so that D = eps_p / eps_cr
//   in uniaxial tension: eps_cr is the failure strain of uniaxial tension. Equibiaxial tension
//   (T = 2/3) fails at eps_cr / e^(1/2) = 0.61 eps_cr, pure shear (T = 0) at sqrt(3) eps_cr,
//   and states at T <= -1/3 (uniaxial compression and below) never. eps_cr either given
//   (critical_strain, for a known element size) or scaled with the element length as in
//   Toernqvist's thesis: eps_cr(l_e) = n + (eps_n - n) t / l_e, n the hardening exponent of the
//   power law sigma = K eps^n (the uniform strain of a tensile test), eps_n the strain in the
//   neck at fracture (measured over a gauge length of about t), t the plate thickness.
//   BWH (Bressan-Williams-Hill; Alsos, Hopperstad, Toernqvist & Amdahl, IJSS 45 (2008)
//   2042-2055, applied in Alsos, Amdahl & Hopperstad, IJIE 36 (2009) 875-887): the onset of
//   local necking of a plate in stress space. With sigma_1 >= sigma_2 the principal stresses
//   in the plate's plane (the through-thickness stress neglected: plane stress),
//   alpha = sigma_2 / sigma_1 and the strain ratio of proportional J2 flow
//   beta = (2 alpha - 1) / (2 - alpha), the limit of the major stress with the power law
//   sigma = K eps^n is
//     sigma_1* = (2K / sqrt 3) (1 + beta / 2) / sqrt(beta^2 + beta + 1)
//                * ((2 / sqrt 3) eps_3 sqrt(beta^2 + beta + 1) / (1 + beta))^n   -1 < beta <= 0
//                                                                              (Hill)
//     sigma_1* = (2K / sqrt 3) ((2 / sqrt 3) eps_3)^n / sqrt(1 - (beta / (2 + beta))^2)
//                                                                     0 < beta <= 1
//                                             (Bressan-Williams: a critical through-thickness
//                                              shear stress, fixed at plane strain beta = 0)
//   with eps_3 = n the critical thickness strain of the papers; continuous at beta = 0. States
//   with sigma_1 <= 0 or alpha <= -1 (beta <= -1: in-plane shear and compression-dominated)
//   never neck. The papers' criterion is the instant the stress state reaches the limit (the
//   limit in stress space being nearly path-independent, no damage sum is kept): here a
//   point's D is the largest sigma_1 / sigma_1* of the plastic steps it went through (a step
//   in which eps_p grows), so D = 1 when it reaches the limit. Size scaling (optional, the
//   same form as RTCL's): the critical thickness strain eps_3 = n + (eps_n - n) t / l_e in
//   place of n in the bracket (the exponent stays n); without t and eps_n, eps_3 = n.
//   The plate's plane at a point: the element's, normal to its thinnest parametric direction
//   at the centre (hexahedra only: a tetrahedron has none).
// erosion: a failed element is removed from the model (explicit analyses only; see
// MaterialContribution and StructuralSolver).
struct FailureCriterion {
  enum class Kind { None, Constant, GermanischerLloyd, Rtcl, Bwh };
  Kind kind = Kind::None;
  double strain = 0.0;          // constant: eps_f; RTCL: eps_cr when given (0: scaled)
  double uniform_strain = 0.0;  // GL: eps_g
  double necking_strain = 0.0;  // GL: eps_e; RTCL, BWH scaling: eps_n (0: BWH unscaled)
  double thickness = 0.0;       // GL: t [m]; RTCL, BWH scaling: t (0: not scaled)
  double hardening_exponent = 0.0;    // RTCL scaling, BWH: n
  double strength_coefficient = 0.0;  // BWH: K [Pa]
  bool erosion = false;

  // Throw Error unless strain > 0 (constant) / eps_g >= 0, eps_e >= 0, t > 0 (GL).
  static FailureCriterion constant(double strain, bool erosion = false);
  static FailureCriterion germanischer_lloyd(double thickness, double uniform_strain = 0.056,
                                             double necking_strain = 0.54, bool erosion = false);
  // RTCL with eps_cr given (> 0), or scaled: t > 0, 0 < n < 1, eps_n >= n.
  static FailureCriterion rtcl(double critical_strain, bool erosion = false);
  static FailureCriterion rtcl_scaled(double thickness, double hardening_exponent,
                                      double neck_strain, bool erosion = false);
  // BWH: K > 0 [Pa], 0 < n < 1; scaled when thickness > 0 (then eps_n >= n), else not.
  static FailureCriterion bwh(double strength_coefficient, double hardening_exponent,
                              double thickness = 0.0, double neck_strain = 0.0,
                              bool erosion = false);
  bool active() const { return kind != Kind::None; }
  // RTCL and BWH: a damage per quadrature point (the others compare the mean eps_p)
  bool uses_damage() const { return kind == Kind::Rtcl || kind == Kind::Bwh; }
  // eps_f of an element of length l_e [m] (infinite when inactive); RTCL: its eps_cr;
  // BWH: its critical thickness strain eps_3.
  double failure_strain(double element_length) const;
  // RTCL and BWH: a point's damage after a committed step that ended at Cauchy stress `sigma`
  // with plastic strain increment d_eps_p >= 0; `critical` is failure_strain(l_e) of its
  // element and `normal` the unit normal of its plate (BWH: the in-plane stresses less the
  // stress through the thickness, the plane-stress state with the same deviator).
  double updated_damage(double damage, const Mat3& sigma, double d_eps_p, double critical,
                        const Vec3& normal) const;
};

// RTCL's weight f(T) of the stress triaxiality T (1 at T = 1/3).
double rtcl_weight(double triaxiality);
// BWH's limit sigma_1* [Pa] of the major in-plane principal stress at stress ratio alpha =
// sigma_2 / sigma_1 (infinite for alpha <= -1), K, n and the critical thickness strain eps_3.
double bwh_limit_stress(double alpha, double strength_coefficient, double hardening_exponent,
                        double critical_thickness_strain);

// l_e of an element as FailureCriterion defines it [m].
double failure_element_length(const Mesh& mesh, const Element& element);
// The unit normal of a hexahedron's plate plane: its thinnest parametric direction dX/dxi_J at
// the centre (BWH). Throws Error for other element types.
Vec3 failure_plate_normal(const Mesh& mesh, const Element& element);

}  // namespace partita::fem
