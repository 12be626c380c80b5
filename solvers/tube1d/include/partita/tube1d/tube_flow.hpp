#pragma once
// Quasi-1D incompressible flow in a tube of varying cross-section a(x, t), unknowns velocity u
// and pressure p at the N + 1 nodes (the preCICE tutorial's fluid solver):
//
//   continuity  d(a)/dt + d(a u)/dx = 0
//   momentum    d(a u)/dt + d(a u^2)/dx + (a / rho) dp/dx = 0
//
// Implicit Euler in time, central fluxes at the cell faces (F_{i+1/2} = (a_i + a_{i+1})(u_i +
// u_{i+1}) / 4), the nonlinear system solved by Newton's method with the exact Jacobian and a
// sparse LU. Boundaries: inlet velocity u_0 = u_in(t_{n+1}); inlet pressure extrapolated linearly
// (p_0 - 2 p_1 + p_2 = 0); outlet velocity extrapolated linearly; non-reflecting outlet
//   p_N = 2 rho (c^2 - (sqrt(c^2 - p_N^n / (2 rho)) - (u_N - u_N^n) / 4)^2).
//
// Call order: set_area(a_{n+1}) (the area at the end of the step); advance(dt); velocity(),
// pressure(). The state (u, p, a at t_n and t) is a plain value: copy it to checkpoint.

#include <Eigen/Core>

#include "partita/tube1d/tube_parameters.hpp"

namespace partita::tube1d {

class TubeFlow {
 public:
  struct State {
    Eigen::VectorXd velocity, pressure, area;  ///< at the nodes, at time t
    double time = 0.0;
  };

  explicit TubeFlow(TubeParameters parameters);

  const TubeParameters& parameters() const { return parameters_; }
  /// The area at the end of the next step (N + 1 values) [m^2].
  void set_area(const Eigen::VectorXd& a);
  /// One implicit Euler step of length dt. Throws std::runtime_error if Newton fails.
  void advance(double dt);

  const Eigen::VectorXd& velocity() const { return state_.velocity; }
  const Eigen::VectorXd& pressure() const { return state_.pressure; }
  const Eigen::VectorXd& area() const { return state_.area; }
  double time() const { return state_.time; }
  const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  /// Newton iterations of the last step.
  int newton_iterations() const { return newton_iterations_; }
  /// Mass flux a u at face i + 1/2 in the discrete form: (a_i + a_{i+1})(u_i + u_{i+1}) / 4.
  double face_flux(int i) const;

 private:
  /// Residual R(u, P) of the discrete equations (P = p / rho) and, if wanted, J = -dR/d(u, P).
  void residual(const Eigen::VectorXd& u, const Eigen::VectorXd& P, double dt, double t_new,
                Eigen::VectorXd& r) const;

  TubeParameters parameters_;
  State state_;
  Eigen::VectorXd next_area_;
  int newton_iterations_ = 0;
};

}  // namespace partita::tube1d
