#pragma once
#include <Eigen/SparseCholesky>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_mesh.hpp"
#include "partita/fem/face_quadrature_point.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/solver_options.hpp"
#include "partita/fem/solver_state.hpp"
#include "partita/fem/solver_timings.hpp"

namespace partita::fem {

// Static and transient (Newmark) small-strain linear elasticity on a Model.
//
// Dofs are node-major: dof 3 i + c is component c of node i. Dirichlet dofs are eliminated
// (partitioned: free f / constrained c), so a factorisation depends on dt and on which dofs
// are constrained, never on the prescribed values or loads.
//
// Call order:
//   1. Solver solver(model, options);            assembles K (and M on first transient use)
//   2. (coupling set-up) face_mesh(face), face_quadrature_points(face): geometry in the
//      reference configuration; quadrature points are ordered by surface element, then by
//      the face rule's points.
//   3. optionally solve_static() for an equilibrium start at time() (velocity = acceleration = 0)
//   4. per time step / coupling window:
//        set_face_tractions_at_quadrature_points(face, T)   T: Nq x 3 [Pa], held until reset
//        set_nodal_forces(nodes, F)                         F: N x 3 [N],  held until reset
//        [implicit coupling: state = save_state() at the window start]
//        step(dt)                                           time() += dt
//        displacement(), face displacements, reaction(set), monitors ...
//        [implicit coupling, not converged: restore_state(state), new loads, step(dt) again]
//   The first step() computes the initial acceleration from M a = F - K u - C v (lumped: a
//   division; consistent: Jacobi-CG to round-off) unless a static solve or a restored state
//   provides it. The effective matrix
//   K + gamma/(beta dt) C + 1/(beta dt^2) M is factorised on the first step and whenever dt
//   changes; otherwise each step is one right-hand side and one pair of triangular solves.
class Solver {
 public:
  explicit Solver(Model model, SolverOptions options = {});
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  const Model& model() const { return model_; }
  const Mesh& mesh() const { return model_.mesh(); }
  const SolverOptions& options() const { return options_; }
  std::size_t num_dofs() const { return ndof_; }

  // --- coupling geometry (reference configuration) ---
  FaceMesh face_mesh(const std::string& face) const;
  std::vector<FaceQuadraturePoint> face_quadrature_points(const std::string& face) const;

  // --- coupling loads (held until replaced; part of the saved state) ---
  // One traction [Pa] per quadrature point of the face, in face_quadrature_points() order:
  // f_a = sum_q N_a(x_q) t_q w_q. Replaces earlier tractions on that face.
  void set_face_tractions_at_quadrature_points(const std::string& face, const MatrixX3& tractions);
  // One force [N] per listed node; replaces all earlier nodal forces.
  void set_nodal_forces(const std::vector<std::size_t>& nodes, const MatrixX3& forces);
  void clear_coupling_loads();

  // --- analyses ---
  // K u = F(time()) with the prescribed values at time(); velocity = acceleration = 0.
  void solve_static();
  // One Newmark step from time() to time() + dt.
  void step(double dt);
  // Quasi-static step: time() += dt, then solve_static() with the loads at the new time.
  void step_static(double dt);
  double time() const { return time_; }
  std::size_t step_count() const { return steps_; }

  // --- results ---
  const Eigen::VectorXd& displacement() const { return u_; }
  const Eigen::VectorXd& velocity() const { return v_; }
  const Eigen::VectorXd& acceleration() const { return a_; }
  Vec3 displacement(std::size_t node) const {
    return u_.segment<3>(3 * static_cast<Eigen::Index>(node));
  }
  MatrixX3 displacements(const std::vector<std::size_t>& nodes) const;
  // Sum over the set's nodes of the nodal residual K u + C v + M a - F [N]: the force the
  // supports exert on the body. (Zero, up to round-off, on nodes without Dirichlet dofs.)
  Vec3 reaction(const std::string& node_set) const;
  // Stresses (Voigt, Pa) evaluated in each element at its nodes and averaged over the
  // elements that share a node (N x 6), and von Mises of those (N).
  MatrixX6 nodal_stress() const;
  static Eigen::VectorXd von_mises(const MatrixX6& stress);
  // F(time()): model loads at time() plus coupling loads [N per dof].
  const Eigen::VectorXd& external_force() const { return f_; }

  // --- scalar monitors ---
  double kinetic_energy() const;                           // 1/2 v^T M v
  double strain_energy() const;                            // 1/2 u^T K u
  double external_work() const { return external_work_; }  // sum 1/2 (F_n + F_n+1).(u_n+1 - u_n)
  double max_displacement() const;                         // max over nodes of |u|
  Vec3 total_coupling_force() const;                       // sum of the coupling loads [N]
  Vec3 total_external_force() const;                       // sum of F(time()) [N]

  // --- state ---
  SolverState save_state() const;
  void restore_state(const SolverState& state);

  const SolverTimings& timings() const { return timings_; }

 private:
  using Factorisation = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>;
  // Face load operator: f[node] += coefficient * t_q for each (node, qp, coefficient).
  struct FaceOperator {
    std::vector<std::size_t> node;
    std::vector<std::size_t> qp;
    std::vector<double> coefficient;
    std::size_t num_qp = 0;
  };

  void setup_dofs();
  void assemble_stiffness();
  void assemble_mass();
  void assemble_loads();
  const FaceOperator& face_operator(const std::string& face) const;
  void update_coupling_force();
  void evaluate_external_force(double t, Eigen::VectorXd& f) const;
  void prescribed_values(double t, Eigen::VectorXd& uc) const;
  void initialise_acceleration();
  void factorise_dynamic(double dt);
  void partition(const SparseMatrix& a, SparseMatrix& aff, SparseMatrix& afc) const;

  Model model_;
  SolverOptions options_;
  ElementIntegrator integrator_;
  std::size_t ndof_ = 0;

  // dof partition
  std::vector<Eigen::Index> free_index_;  // -1 for constrained dofs
  std::vector<Eigen::Index> free_dofs_, constrained_dofs_;
  std::vector<SpaceTimeFunction> constrained_value_;  // per constrained dof (empty: zero)

  // matrices (full and partitioned)
  SparseMatrix k_, m_, k_ff_, k_fc_, m_ff_, m_fc_, keff_fc_;
  bool mass_ready_ = false;
  std::unique_ptr<Factorisation> static_factor_, dynamic_factor_;
  double factor_dt_ = -1.0;

  // loads
  std::vector<Eigen::VectorXd> load_vectors_;  // per model load, at unit amplitude
  mutable std::map<std::string, FaceOperator> face_operators_;
  std::map<std::string, MatrixX3> face_tractions_;
  std::vector<std::size_t> nodal_force_nodes_;
  MatrixX3 nodal_forces_;
  Eigen::VectorXd coupling_force_;

  // state
  double time_ = 0.0;
  std::size_t steps_ = 0;
  Eigen::VectorXd u_, v_, a_, f_;
  bool acceleration_valid_ = false;
  struct Work {  // vectors of a dynamic step, kept between steps
    Eigen::VectorXd f1, pm, pc, rhs, uc, rf, uf, u1, a1;
  };
  Work work_;
  double external_work_ = 0.0;

  SolverTimings timings_;
};

}  // namespace partita::fem
