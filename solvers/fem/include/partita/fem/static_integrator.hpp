#pragma once
#include <string>
#include <vector>

#include "partita/fem/newton_solver.hpp"
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Nonlinear static equilibrium f_int(u) = F on the free dofs, u_c prescribed, by load stepping:
// from the current state (F_0 = f_int(u_0) on the free dofs, the applied load on the
// constrained ones; u_c,0) to the target (F(t1), g(t1)) along
//   F(lambda) = F_0 + lambda (F(t1) - F_0),  u_c(lambda) = u_c,0 + lambda (g(t1) - u_c,0),
// lambda from 0 to 1 in NewtonOptions::load_steps increments; a failed increment is halved
// (automatic cut-back; the following increments keep the halved size), at most max_cutbacks
// times in a row and never below 1/2^max_cutbacks of the initial increment; the history is
// committed after each converged increment. After max_cutbacks
// halvings in a row it throws Error: a limit load (the load factor had grown, then stopped with
// a singular tangent, a stagnating or growing residual: the message gives the largest load
// factor reached), or the load step, lambda, the residual, the tolerance and what the Newton
// failure was (a stall at round-off, divergence, an inverted element ...).
//
// A limit load is also told where Newton keeps converging: a structure past its collapse load
// whose model keeps a trace of stiffness (an element's residual constraint, the supports'
// triaxiality) lets the load factor creep on while the displacement runs away. When an increment
// is accepted with a node moved more than the model's size (set_model_size: the diagonal of
// its bounding box) and a secant stiffness |dF| / |du| (dF the increment's change of the loads)
// below kRunawayStiffness of the first loaded increment's (of the first solve: the structure at
// rest), it throws Error with "limit load" and the largest load factor carried: the last one
// reached by an increment that kept at least that fraction of the stiffness at rest.
class StaticIntegrator {
 public:
  explicit StaticIntegrator(NewtonOptions options = {},
                            LinearSolver linear_solver = LinearSolver::Automatic,
                            FillOrdering ordering = FillOrdering::Automatic,
                            FactorThreading factor_threading = FactorThreading::Automatic)
      : newton_(options, linear_solver, ordering, factor_threading) {}
  // Velocity and acceleration are set to zero; kin.time = t1.
  void solve(StructuralSystem& system, Kinematics& kin, double t1);
  // The runaway test above (0: off, the default).
  void set_model_size(double size) { model_size_ = size; }
  // The fraction of the first increment's secant stiffness below which an increment counts as
  // a runaway: 1 %, the stiffness of a perfectly plastic hinge or a hardening of E/100 and less
  // (a beam's section keeps about H/E of its bending stiffness once fully plastic).
  static constexpr double kRunawayStiffness = 0.01;
  // Reports of the Newton solves of the last solve() (converged increments and failures).
  const std::vector<NewtonReport>& reports() const { return reports_; }
  // Newton iterations and cut-backs as text (see ProgressCallback).
  void set_progress(ProgressCallback progress) {
    progress_ = progress;
    newton_.set_progress(std::move(progress));
  }

 private:
  std::string failure_message(const NewtonReport& rep, int step, double lambda, double next,
                              double t1, double stiffness_first, double stiffness_last) const;
  NewtonSolver newton_;
  ProgressCallback progress_;
  double model_size_ = 0.0;
  double reference_stiffness_ = 0.0;  // of the runaway test: the first loaded increment's
  std::vector<NewtonReport> reports_;
};

}  // namespace partita::fem
