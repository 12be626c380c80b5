#pragma once
#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// One term of the FE operator of the nonlinear path, f(u) = sum_c f_c(u), K(u) = sum_c K_c(u)
// (NonlinearOperator sums them, as MFEM's NonlinearForm sums its integrators): the material's
// internal force (MaterialContribution) is one; a rigid indenter's contact force, a follower
// load or a spring bed are others, added with NonlinearOperator::add_contribution() without
// touching the Newton solver or the time integrators (static, Newmark, central difference),
// which see only the sum.
//
// Call order:
//   coupled_node_groups() once, when the operator builds its tangent's sparsity pattern;
//   set_time(t, fraction) before the add()s of a step (a contribution that moves with time, a
//     rigid indenter, places itself there from its committed state);
//   add(u, f, k, assembler) any number of times (Newton iterations, line searches, explicit
//     steps): from the committed state, leaving a trial state for u;
//   commit() when the step is accepted (the trial state becomes the committed one); a rejected
//     step simply calls add() again;
//   committed_state() / set_committed_state() for restart files, at any time between steps.
class OperatorContribution {
 public:
  virtual ~OperatorContribution() = default;
  virtual std::string_view name() const = 0;
  // Groups of nodes whose dofs the tangent couples beyond the mesh's elements (each group as an
  // element: every pair of its nodes); a contribution whose K_c couples only nodes that share
  // an element, or a node with itself (contact with a rigid body), returns none.
  virtual std::vector<std::vector<std::size_t>> coupled_node_groups() const { return {}; }
  // The configuration the next add()s are at: `fraction` of the way from the step's start to t
  // (the static integrator's load factor; 1 in dynamics). fraction 0 marks a step's start: the
  // committed state itself, whose time the following fractions count from. Only contributions
  // that depend on time (a moving rigid body) use it.
  virtual void set_time(double /*t*/, double /*fraction*/) {}
  // A bound of the largest eigenvalue of M^-1 K_c (K_c this contribution's stiffness, M the
  // lumped mass, per node: nodal_mass) [1/s^2]: the explicit solver adds it to the elements'
  // omega_max^2 for its stable step. 0: the contribution does not lower it.
  virtual double max_frequency_squared(const Eigen::VectorXd& /*nodal_mass*/) const { return 0.0; }
  // f += f_c(u) over all dofs (node-major, 3 per node); when k != nullptr also k += K_c(u),
  // added through `assembler` (whose pattern k has). May throw Error where u is inadmissible.
  virtual void add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
                   const BlockAssembler& assembler) = 0;
  // False for a contribution that offers no tangent (explicit analyses only): the operator then
  // refuses to assemble K for an implicit one, naming the contribution.
  virtual bool has_tangent() const { return true; }
  virtual void commit() {}
  // Recoverable energy stored by the contribution at the u of the last add() [J] (the
  // material's strain energy; a penalty contact's spring energy).
  virtual double stored_energy() const { return 0.0; }
  // Energy dissipated in the committed state [J] (plastic work; frictional work).
  virtual double dissipated_work() const { return 0.0; }
  // Round-off bound of the f_c of the last add() [N] (see NewtonSolver).
  virtual double round_off() const { return 0.0; }
  // The committed state, flattened (empty without history), and its restoration.
  virtual const std::vector<double>& committed_state() const;
  virtual void set_committed_state(const std::vector<double>& state);
};

// The committed states of several contributions, one after the other (an operator's state), and
// its split back into them; `owner` names the operator in the error for a state of another size.
void gather_committed_states(const std::vector<std::unique_ptr<OperatorContribution>>& contributions,
                             std::vector<double>& state);
void scatter_committed_states(const std::vector<std::unique_ptr<OperatorContribution>>& contributions,
                              const std::vector<double>& state, std::string_view owner);

}  // namespace partita::fem
