#pragma once
#include <span>
#include <string_view>

#include "partita/fem/material.hpp"
#include "partita/fem/material_response.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// What an evaluation knows of its step besides F and the history: the time from the committed
// state to the evaluated one, for rate-dependent laws (the J2 laws' strain-rate hardening,
// strain_rate_law.hpp). Rate-independent laws ignore it.
//   dynamic false (static analyses, and callers that know no time: the default): rate terms off,
//     the law as it is without them;
//   dynamic true: time_increment dt >= 0 [s] is physical time since the committed state; a
//     rate-dependent law takes its rates as increments over dt (dt = 0, an evaluation at the
//     committed instant itself, leaves no time for viscous flow).
struct MaterialStep {
  double time_increment = 0.0;
  bool dynamic = false;
};

// A constitutive law: stress and tangent from the deformation gradient F and the history of a
// quadrature point. The law is stateless itself; the operator owns the history.
//
// Call order (per quadrature point):
//   1. initialise_state(committed) once (history at rest)
//   2. evaluate(F, committed, trial, response) any number of times (Newton iterations,
//      line search): reads the committed history, writes the trial history, never changes
//      the committed one
//   3. on acceptance of a step the operator copies trial -> committed; on rejection it keeps
//      the committed history and evaluates again.
// Small-strain laws use eps = sym(F - I) and return sigma as P, so the same operator serves
// both kinematics.
class MaterialLaw {
 public:
  virtual ~MaterialLaw() = default;

  virtual std::string_view name() const = 0;
  virtual double density() const = 0;  // rho [kg/m^3] in the reference configuration
  // Dilatational (P-) wave speed of the undeformed material c_d = sqrt((lambda + 2 mu) / rho).
  virtual double dilatational_wave_speed() const = 0;
  // Bulk modulus K = lambda + 2/3 mu at rest [Pa].
  virtual double bulk_modulus() const = 0;
  // The isotropic small-strain constants at rest (Young's modulus, Poisson's ratio, density):
  // what the solver reads whatever the law (the linear path's stiffness and stresses, the
  // contact penalty). Default: from the bulk modulus and the dilatational wave speed
  // (rho c_d^2 = K + 4/3 mu); a law made of E, nu and rho returns those.
  virtual Material small_strain_material() const;

  // True for the small-strain laws (eps = sym(F - I)): their `stress` is the Cauchy stress
  // sigma itself, used as P by the operator; false for finite-strain laws, whose `stress` is P
  // and whose Cauchy stress is P F^T / J.
  virtual bool small_strain() const { return false; }
  // Number of history values per quadrature point (0 for elastic laws).
  virtual int state_size() const { return 0; }
  virtual void initialise_state(std::span<double> state) const;
  virtual void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                        MaterialResponse& response) const = 0;
  // evaluate() without the tangent (response.tangent is left as it was; stress, energy and the
  // trial history are those of evaluate(), bit for bit): what explicit steps call, which need
  // no tangent. The default calls evaluate(); a law whose tangent costs much overrides it.
  virtual void evaluate_stress(const Mat3& f, std::span<const double> committed,
                               std::span<double> trial, MaterialResponse& response) const {
    evaluate(f, committed, trial, response);
  }
  // evaluate() and evaluate_stress() over a step (MaterialStep): what the FE operator calls. The
  // defaults ignore the step and call the forms above, so a rate-independent law defines only
  // those; a rate-dependent law overrides these (and the forms above as these with a default
  // MaterialStep).
  virtual void evaluate_step(const Mat3& f, std::span<const double> committed,
                             std::span<double> trial, const MaterialStep& /*step*/,
                             MaterialResponse& response) const {
    evaluate(f, committed, trial, response);
  }
  virtual void evaluate_step_stress(const Mat3& f, std::span<const double> committed,
                                    std::span<double> trial, const MaterialStep& /*step*/,
                                    MaterialResponse& response) const {
    evaluate_stress(f, committed, trial, response);
  }
  // Plastic work per unit reference volume accumulated in a history [J/m^3] (0 if elastic).
  virtual double plastic_work_density(std::span<const double> state) const;
  // Equivalent plastic strain of a history (0 if elastic).
  virtual double equivalent_plastic_strain(std::span<const double> state) const;
};

// Lame constants from E and nu: lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
struct LameConstants {
  double lambda = 0.0;
  double mu = 0.0;
};
LameConstants lame_constants(double youngs_modulus, double poisson_ratio);

// Throws Error("<law>: ...") unless E > 0, -1 < nu < 0.5 and rho >= 0 (the rule, the value
// found and, for nu, that a compressible law needs nu < 0.5).
void validate_isotropic_constants(std::string_view law, double youngs_modulus, double poisson_ratio,
                                  double density);
// Throws Error("<law>: deformation gradient with det F = j <= 0 ...") unless j > 0.
void require_positive_jacobian(std::string_view law, double j);

// C_iJkL = lambda d_iJ d_kL + mu (d_ik d_JL + d_iL d_Jk) as a 9 x 9 matrix.
Matrix9 isotropic_elasticity_tensor(double lambda, double mu);

}  // namespace partita::fem
