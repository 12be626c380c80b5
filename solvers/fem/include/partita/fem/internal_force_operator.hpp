#pragma once
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem {

// The structure's internal force f_int(u) and its tangent K_t(u) = d f_int / du over all dofs
// (node-major, 3 per node), with the history of every quadrature point.
//
// Call order:
//   evaluate(u, f, &K) any number of times (Newton iterations, line searches): each evaluation
//     starts from the committed history and leaves a trial history for u;
//   commit() when the step is accepted: the trial history of the last evaluate() becomes the
//     committed one. A rejected step simply evaluates again.
class InternalForceOperator {
 public:
  virtual ~InternalForceOperator() = default;
  // f_int(u); K_t(u) as well when k != nullptr (k keeps its sparsity pattern once set).
  virtual void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k) = 0;
  virtual void commit() = 0;
  // The flag of a constant tangent: K when f_int(u) = K u with K fixed (linear elasticity), so
  // that an integrator factorises its matrix once per step size and solves each step with one
  // right-hand side, as deal.II's and MFEM's steppers do; nullptr (the default) when the tangent
  // changes with u (Newton). The matrix is referenced: it lives as long as the operator.
  virtual const SparseMatrix* constant_tangent() const { return nullptr; }
  // The time of the next evaluations: `fraction` of the way from the committed time to t (see
  // OperatorContribution::set_time; integrators call it before evaluating a step). Only time-
  // dependent terms (a moving rigid indenter) use it.
  virtual void set_time(double /*t*/, double /*fraction*/) {}
  // Estimate of the round-off error of the f_int of the last evaluate() [N] (a norm over all
  // dofs): what double precision allows a Newton residual to reach (see NewtonSolver).
  virtual double round_off() const = 0;
  // Stored energy int W dV at the u of the last evaluate() [J].
  virtual double strain_energy() const = 0;
  // Plastic work int w_p dV of the committed history [J].
  virtual double plastic_work() const = 0;
  // Committed history of all quadrature points, flattened (empty for elastic laws).
  virtual const std::vector<double>& committed_state() const = 0;
  virtual void set_committed_state(const std::vector<double>& state) = 0;
};

}  // namespace partita::fem
