// StructuralSolver: the state saved at a window's start and restored (implicit coupling, restart
// files).
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem {

SolverState StructuralSolver::save_state() const {
  SolverState s;
  s.time = kin_.time;
  s.steps = steps_;
  s.displacement = kin_.u;
  s.velocity = kin_.v;
  s.acceleration = kin_.a;
  s.external_force = kin_.f;
  s.acceleration_valid = acceleration_valid_;
  s.external_work = kin_.external_work;
  s.damping_work = kin_.damping_work;
  s.material_state = operator_->committed_state();
  s.coupling_force = coupling_force_;
  s.face_tractions = face_tractions_;
  s.nodal_force_nodes = nodal_force_nodes_;
  s.nodal_forces = nodal_forces_;
  s.factor_dt = newmark_.factor_dt();
  return s;
}

void StructuralSolver::restore_state(const SolverState& s) {
  const auto n = static_cast<Eigen::Index>(ndof_);
  if (s.displacement.size() != n || s.velocity.size() != n || s.acceleration.size() != n ||
      s.external_force.size() != n || s.coupling_force.size() != n) {
    throw Error("restore_state: the state has " + std::to_string(s.displacement.size()) +
                " dofs but this solver has " + std::to_string(ndof_) +
                " (state of another model?)");
  }
  kin_.time = s.time;
  steps_ = s.steps;
  kin_.u = s.displacement;
  kin_.v = s.velocity;
  kin_.a = s.acceleration;
  kin_.f = s.external_force;
  acceleration_valid_ = s.acceleration_valid;
  kin_.external_work = s.external_work;
  kin_.damping_work = s.damping_work;
  operator_->set_committed_state(s.material_state);
  coupling_force_ = s.coupling_force;
  face_tractions_ = s.face_tractions;
  nodal_force_nodes_ = s.nodal_force_nodes;
  nodal_forces_ = s.nodal_forces;
  // A state from another process (a restart file) carries the step size the factorisation was
  // made for; the same h gives the same K_eff and the same steps, bit for bit.
  if (s.factor_dt > 0.0 && s.factor_dt != newmark_.factor_dt()) {
    assemble_mass();  // K_eff needs M (assembled lazily at the first step)
    newmark_.factorise(*this, s.factor_dt);
  }
  if (nonlinear_ != nullptr && nonlinear_->material().erosion() && mass_ready_) {
    // the eroded elements of this state, not those of the last: the lumped mass again
    mass_ready_ = false;
    assemble_mass();
    central_.invalidate_mass();
  }
  if (uses_newton() || options_.integrator == Integrator::CentralDifference) {
    refresh_internal_force();
  }
}

}  // namespace partita::fem
