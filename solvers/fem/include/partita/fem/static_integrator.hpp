#pragma once
#include <memory>
#include <string>
#include <vector>

#include "partita/fem/linear_solver.hpp"
#include "partita/fem/newton_solver.hpp"
#include "partita/fem/solver_timings.hpp"
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Static equilibrium f_int(u) = F(t1) on the free dofs, u_c = g(t1) prescribed.
//
// Constant tangent (InternalForceOperator::constant_tangent(): f_int = K u, linear elasticity):
// one linear system, K_ff u_f = F_f - K_fc u_c, with K_ff factorised at the first solve and kept
// for the following ones (the tangent and the constrained dofs do not change).
//
// Otherwise nonlinear, by load stepping:
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
      : newton_(options, linear_solver, ordering, factor_threading),
        linear_solver_(linear_solver),
        ordering_(ordering),
        factor_threading_(factor_threading) {}
  ~StaticIntegrator();
  // Velocity and acceleration are set to zero; kin.time = t1.
  void solve(StructuralSystem& system, Kinematics& kin, double t1);
  // Constant tangent: the threading of the triangular solves of K_ff's factor, and where its
  // factorisation is counted (optional); set before the first solve.
  void set_solve_threading(SolveThreading threading) { solve_threading_ = threading; }
  void set_timings(SolverTimings* timings) { timings_ = timings; }
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
  void solve_constant_tangent(StructuralSystem& system, Kinematics& kin, const SparseMatrix& k,
                              double t1);
  std::string failure_message(const NewtonReport& rep, int step, double lambda, double next,
                              double t1, double stiffness_first, double stiffness_last) const;
  NewtonSolver newton_;
  ProgressCallback progress_;
  double model_size_ = 0.0;
  double reference_stiffness_ = 0.0;  // of the runaway test: the first loaded increment's
  std::vector<NewtonReport> reports_;
  // constant tangent: K_ff's factor (for the matrix factored_), and K's partitioned blocks
  LinearSolver linear_solver_;
  FillOrdering ordering_;
  FactorThreading factor_threading_;
  SolveThreading solve_threading_ = SolveThreading::Automatic;
  SolverTimings* timings_ = nullptr;
  std::unique_ptr<SparseFactorisation> factor_;
  const SparseMatrix* factored_ = nullptr;
  SparseMatrix k_ff_, k_fc_;
};

}  // namespace partita::fem
