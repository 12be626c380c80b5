#pragma once
#include <vector>

#include "partita/fem/dof_partition.hpp"
#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// What a time integrator sees of a structure:
//   M a + C v + f_int(u) = F(t) on the free dofs,  u = g(t) on the constrained dofs,
// with Rayleigh damping C = alpha M + beta K0, K0 the tangent stiffness at rest (u = 0, initial
// history): a constant, linear damping (see SolverOptions). Vectors span all dofs (node-major).
class StructuralSystem {
 public:
  virtual ~StructuralSystem() = default;
  virtual const DofPartition& dofs() const = 0;
  virtual InternalForceOperator& internal_forces() = 0;
  // M over all dofs (assembled on first use); diagonal when lumped.
  virtual const SparseMatrix& mass() = 0;
  virtual bool lumped_mass() const = 0;
  virtual double mass_damping() const = 0;       // alpha of C = alpha M + beta K0
  virtual double stiffness_damping() const = 0;  // beta of C = alpha M + beta K0
  // K0 over all dofs (the tangent at rest, symmetric); only asked for when beta != 0.
  virtual const SparseMatrix& damping_stiffness() = 0;
  virtual void external_force(double t, Eigen::VectorXd& f) const = 0;
  // Writes g(t) into the constrained entries of u.
  virtual void apply_prescribed(double t, Eigen::VectorXd& u) const = 0;
  // g(t) alone, one value per constrained dof (DofPartition::constrained_dofs() order).
  virtual void prescribed_values(double t, Eigen::VectorXd& uc) const = 0;
};

// The evolving kinematic state an integrator advances, and its energy bookkeeping.
struct Kinematics {
  double time = 0.0;
  Eigen::VectorXd u, v, a;
  Eigen::VectorXd f;           // F(time) of the last solve
  Eigen::VectorXd f_int;       // f_int(u) (nonlinear path and explicit steps)
  double external_work = 0.0;  // sum 1/2 (F_n + F_n+1) . (u_n+1 - u_n)
  double damping_work = 0.0;   // sum dt v_n+1/2 . C v_n+1/2
};

}  // namespace partita::fem
