#pragma once
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Explicit central differences with a lumped (diagonal) mass, in velocity-Verlet form:
//   v_1/2 = v + dt/2 a,   u_1 = u + dt v_1/2  (u_c = g(t + dt)),
//   M a_1 + alpha M v_1 + beta K0 v_1/2 = F_1 - f_int(u_1),  v_1 = v_1/2 + dt/2 a_1
//   => a_1 = (M^-1 (F_1 - f_int(u_1) - beta K0 v_1/2) - alpha v_1/2) / (1 + alpha dt/2)
//   per free dof (the mass-proportional part implicit, the stiffness-proportional one lagged);
// prescribed dofs: v_1 = (u_1 - u) / dt, a_1 = 0. The history is committed every step.
// Stable for dt <= 2 / omega_max (see StructuralSolver::stable_time_step()). The state at full
// steps (u, v, a) is all it needs: restoring it continues bit-identically.
// A node without mass (one no element holds any more: erosion, or unused by the mesh) is held
// where it is (a = 0: its mass is taken as the largest double).
class CentralDifferenceIntegrator {
 public:
  void step(StructuralSystem& system, Kinematics& kin, double dt);
  // a = M^-1 (F - f_int(u) - C v) on the free dofs (start of a run).
  void initialise(StructuralSystem& system, Kinematics& kin);
  // The system's mass changed (element erosion): read it again at the next step.
  void invalidate_mass() { m_.resize(0); }

 private:
  void load_mass(StructuralSystem& system);
  Eigen::VectorXd v_half_, f1_, u1_, m_, cv_;
};

}  // namespace partita::fem
