#pragma once
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem {

// Everything that evolves in a StructuralSolver: kinematics, time, the coupling loads that are set,
// the energy bookkeeping. StructuralSolver::restore_state(save_state()) then continuing gives
// bit-identical results.
struct SolverState {
  double time = 0.0;
  std::size_t steps = 0;
  Eigen::VectorXd displacement, velocity, acceleration;
  Eigen::VectorXd external_force;  // F(time) used by the last solve
  bool acceleration_valid = false;
  double external_work = 0.0;
  double damping_work = 0.0;
  std::vector<double> material_state;  // committed quadrature-point history (nonlinear path)
  Eigen::VectorXd coupling_force;
  std::map<std::string, MatrixX3> face_tractions;
  std::vector<std::size_t> nodal_force_nodes;
  MatrixX3 nodal_forces;
  // The step size K_eff was factorised for (-1: none). Steps within 1e-9 of it integrate with
  // exactly this h, so a restart must factorise for the same h to continue bit for bit.
  double factor_dt = -1.0;
};

}  // namespace partita::fem
