#pragma once
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "partita/fem/central_difference_integrator.hpp"
#include "partita/fem/dof_partition.hpp"
#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_load_operator.hpp"
#include "partita/fem/face_mesh.hpp"
#include "partita/fem/failure_event.hpp"
#include "partita/fem/face_quadrature_point.hpp"
#include "partita/fem/linear_contribution_operator.hpp"
#include "partita/fem/linear_solver.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/newmark_integrator.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/operator_contribution.hpp"
#include "partita/fem/region_energies.hpp"
#include "partita/fem/solver_options.hpp"
#include "partita/fem/solver_state.hpp"
#include "partita/fem/solver_timings.hpp"
#include "partita/fem/static_integrator.hpp"
#include "partita/fem/structural_system.hpp"

namespace partita::fem {

// Static and transient structural analysis of a Model.
//
// One operator (InternalForceOperator) and one integrator per analysis: StaticIntegrator,
// NewmarkIntegrator, CentralDifferenceIntegrator (SolverOptions::integrator = CentralDifference:
// explicit dynamics, lumped mass, stable_time_step() the largest stable step). Where the
// operator's tangent is constant the implicit integrators factorise K_ff (static) or K_eff
// (Newmark, once per step size) once and solve each step with one right-hand side; otherwise
// they take Newton (load stepping and cut-back). The operator follows from the model:
//   linear (every region linear elastic, Model::is_linear()): K assembled once (Hex8 with
//     incompatible modes), f_int = K u (LinearElasticOperator: a constant tangent); with operator
//     contributions (a contact) K u plus them (LinearContributionOperator: Newton).
//   nonlinear (a region has a MaterialLaw: neo-hooke, j2-plasticity, ..., or
//     SolverOptions::nonlinear_path): a NonlinearOperator (f_int and K_t element by element,
//     quadrature-point history, plus the contributions).
//
// Dofs are node-major: dof 3 i + c is component c of node i. Dirichlet dofs are eliminated
// (partitioned: free f / constrained c), so a factorisation depends on dt and on which dofs
// are constrained, never on the prescribed values or loads.
//
// Call order:
//   1. StructuralSolver solver(model, options);            assembles K (and M on first transient
//   use)
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
class StructuralSolver final : private StructuralSystem {
 public:
  explicit StructuralSolver(Model model, SolverOptions options = {});
  ~StructuralSolver() override;
  StructuralSolver(const StructuralSolver&) = delete;
  StructuralSolver& operator=(const StructuralSolver&) = delete;

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
  // sum_q w_q t_q . du(x_q) = f(t) . du: the work of tractions t (one row per quadrature point of
  // the face, as above) over the displacement increment du (all dofs) (interface energy audit).
  double face_traction_work(const std::string& face, const MatrixX3& tractions,
                            const Eigen::VectorXd& du) const;

  // --- analyses ---
  // K u = F(time()) with the prescribed values at time(); velocity = acceleration = 0.
  void solve_static();
  // One step from time() to time() + dt: Newmark (linear or Newton) or central difference.
  void step(double dt);
  // Largest stable explicit step (lumped mass): 2 / omega_max with omega_max bounded by the
  // largest element eigenfrequency (element eigenvalue theorem), the elements' K and M at rest
  // restricted to their free dofs. Never above the true limit of the linearised mesh; measured
  // 0.66-1.0 of the observed limit (see README). With stiffness-proportional damping (beta > 0,
  // its force lagged by half a step) the limit is (2 / omega_max)(sqrt(1 + xi^2) - xi) with
  // xi = beta omega_max / 2 (Belytschko, Liu & Moran, Nonlinear Finite Elements for Continua
  // and Structures, 2000, chapter 6); mass-proportional damping is integrated implicitly and
  // does not lower it. Computed once and cached.
  double stable_time_step() const;
  // Quasi-static step: time() += dt, then solve_static() with the loads at the new time.
  void step_static(double dt);
  double time() const { return kin_.time; }
  std::size_t step_count() const { return steps_; }

  // --- results ---
  const Eigen::VectorXd& displacement() const { return kin_.u; }
  const Eigen::VectorXd& velocity() const { return kin_.v; }
  const Eigen::VectorXd& acceleration() const { return kin_.a; }
  Vec3 displacement(std::size_t node) const {
    return kin_.u.segment<3>(3 * static_cast<Eigen::Index>(node));
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
  const Eigen::VectorXd& external_force() const { return kin_.f; }

  // --- scalar monitors ---
  double kinetic_energy() const;  // 1/2 v^T M v
  double strain_energy() const;   // 1/2 u^T K u (linear), int W dV (nonlinear)
  double plastic_work() const;    // int w_p dV of the committed history
  double damping_work() const { return kin_.damping_work; }  // sum dt v.C v
  double external_work() const {
    return kin_.external_work;
  }  // sum 1/2 (F_n + F_n+1).(u_n+1 - u_n)
  // The reduced Hex8's lagged enhanced-strain update: the energy it dissipates [J]
  // (MaterialContribution::enhanced_strain_work(); 0 without reduced Hex8)
  double enhanced_strain_work() const;
  // external work - (strain + kinetic + plastic + damping + eroded + enhanced strain) [J]: zero
  // for an exact energy balance (prescribed displacements do work through the reactions, not
  // counted here).
  double energy_balance() const;
  double max_displacement() const;    // max over nodes of |u|
  Vec3 total_coupling_force() const;  // sum of the coupling loads [N]
  Vec3 total_external_force() const;  // sum of F(time()) [N]

  // --- state ---
  SolverState save_state() const;
  void restore_state(const SolverState& state);

  const SolverTimings& timings() const { return timings_; }
  // Per quadrature point of the nonlinear path (empty on the linear path): equivalent plastic
  // strain and Cauchy stress (Voigt) at the current state.
  Eigen::VectorXd equivalent_plastic_strain() const;
  // Mean over each element's quadrature points (one value per element; empty when linear).
  Eigen::VectorXd element_equivalent_plastic_strain() const;
  // --- rupture and energies by part (structural_solver_failure.cpp) ---
  // With a FailureCriterion in the model (nonlinear path), every step / static solve ends by
  // marking the elements whose committed mean equivalent plastic strain reached their eps_f
  // (RTCL, BWH: whose points' mean damage reached 1, element_damage()) as failed at time().
  // With erosion (central difference only: static and Newmark refuse it at
  // construction, as does stiffness-proportional damping, whose K0 would keep the element) a
  // failed element leaves the internal force and the lumped mass; its strain energy, plastic
  // work and the kinetic energy of its mass go to eroded_energy(); a node left without any
  // element is held where it is. Operator contributions that hold surfaces (contact) can ask
  // element_failed() to drop the faces of eroded elements.
  std::size_t failed_elements() const;
  bool element_failed(std::size_t element) const;
  bool element_eroded(std::size_t element) const;
  // When the element failed (the end of that step) [s]; -1 while it has not.
  double element_failure_time(std::size_t element) const;
  // RTCL, BWH: the committed mean damage of the element's points (-1 under other criteria)
  double element_damage(std::size_t element) const;
  /// True when every element around `node` is eroded: the node has left the structure (and its
  /// surfaces: an indenter no longer touches it).
  bool node_detached(std::size_t node) const;
  // The first element to fail (the earliest time; the lowest id among those of that step).
  std::optional<FailureEvent> first_failure() const;
  double eroded_energy() const;
  RegionEnergies region_energies() const;
  double max_equivalent_plastic_strain() const;  // over all quadrature points (0 if linear)
  // --- mass scaling (SolverOptions::mass_scaling_time_step) ---
  // Element e's density factor s_e >= 1 (1 without mass scaling).
  double mass_scale_factor(std::size_t element) const {
    return mass_scale_.empty() ? 1.0 : mass_scale_[element];
  }
  std::size_t mass_scaled_elements() const;  // elements with s_e > 1
  // The smallest stable step of the elements not eroded at their present shape [s]: each
  // element's own bound at rest, 2 / omega_e (its scaled mass), times its characteristic length
  // now over the one at rest (element_length(): V / A_max; a squeezed element's step shrinks
  // with it, one turned inside out gives 0). The stable step (stable_time_step()) is the bound
  // at rest; an explicit step above this one integrates that element unstably. infinity
  // without elements.
  double min_element_time_step() const;
  double physical_mass() const;  // sum of rho V over the elements not eroded [kg]
  double added_mass() const;     // sum of (s_e - 1) rho V over the elements not eroded [kg]
  // Newton reports of the last nonlinear static solve / Newmark step.
  const std::vector<NewtonReport>& static_reports() const { return static_.reports(); }
  const NewtonReport& newmark_report() const { return newmark_.last_report(); }
  // Newton iterations of the last step() or solve_static() (all load steps, cut-backs and
  // failed tries); 0 where the operator's tangent is constant and for central difference.
  int newton_iterations() const;
  // Adds a contribution to the FE operator beside the material's (OperatorContribution: a
  // contact, a spring bed ...), before the first step or solve. The static, Newmark and
  // central-difference integrators see the sum: on the nonlinear path NonlinearOperator's, on
  // the linear path K u plus the contributions (LinearContributionOperator, still one sparse
  // product for K u), whose tangent is not constant: static and Newmark take Newton on it.
  // The Rayleigh K0 stays the material's tangent at rest.
  void add_contribution(std::unique_ptr<OperatorContribution> contribution);
  // Newton iterations, load steps and cut-backs of the nonlinear path as lines of text (the
  // library does not log; the FEM adapter passes them to its logger at debug level).
  void set_progress_callback(ProgressCallback progress) {
    static_.set_progress(progress);
    newmark_.set_progress(std::move(progress));
  }

 private:
  // --- set-up and assembly (structural_solver_assembly.cpp) ---
  void setup_dofs();
  void assemble_stiffness();
  void assemble_mass();  // once, at the first transient use (again after erosion)
  void assemble_loads();
  // --- faces and loads (structural_solver_loads.cpp) ---
  const FaceLoadOperator& face_operator(const std::string& face) const;
  void update_coupling_force();
  void evaluate_external_force(double t, Eigen::VectorXd& f) const;
  // --- analyses (structural_solver.cpp) ---
  void initialise_acceleration();
  void refresh_internal_force();
  // Static and Newmark solve with Newton on the operator (the nonlinear path, or the linear
  // path with contributions), not with a factorise-once K_ff (or K_eff): the operator has no
  // constant tangent. Its internal force f_int(u) is then kept in kin_.f_int.
  bool uses_newton() const { return operator_->constant_tangent() == nullptr; }
  // r += sign C v with C = alpha M + beta K0 (M assembled).
  void add_damping_force(const Eigen::VectorXd& v, double sign, Eigen::VectorXd& r) const;
  // --- StructuralSystem: what the integrators see ---
  const DofPartition& dofs() const override { return dofs_; }
  InternalForceOperator& internal_forces() override { return *operator_; }
  const SparseMatrix& mass() override;
  bool lumped_mass() const override { return options_.mass == MassType::Lumped; }
  double mass_damping() const override { return options_.rayleigh_alpha; }
  double stiffness_damping() const override { return options_.rayleigh_beta; }
  const SparseMatrix& damping_stiffness() override { return nonlinear_ != nullptr ? k0_ : k_; }
  void external_force(double t, Eigen::VectorXd& f) const override;
  void apply_prescribed(double t, Eigen::VectorXd& u) const override;
  void prescribed_values(double t, Eigen::VectorXd& uc) const override;
  // --- mass scaling and the stable step (structural_solver_mass.cpp) ---
  // the density element e's mass is built with: the model's times its mass-scaling factor
  double element_density(std::size_t e) const {
    return model_.density(mesh().elements()[e].region) * mass_scale_factor(e);
  }
  // per element: lambda_max(M_e^-1 K_e) on its free dofs with the physical density (0 when it
  // has none), computed once (stable_time_step() and the mass scaling)
  const std::vector<double>& element_frequencies_squared() const;
  void setup_mass_scaling();
  // --- failure (structural_solver_failure.cpp) ---
  void validate_failure_setup() const;
  void update_failures();  // after each step: see failed_elements()

  Model model_;
  SolverOptions options_;
  ElementIntegrator integrator_;
  std::size_t ndof_ = 0;

  // dof partition
  DofPartition dofs_;
  std::vector<SpaceTimeFunction> constrained_value_;  // per constrained dof (empty: zero)
  mutable Eigen::VectorXd prescribed_work_;           // apply_prescribed()'s buffer

  // matrices (full and partitioned)
  SparseMatrix k_, m_, m_ff_, m_fc_;
  SparseMatrix k0_;  // nonlinear path with rayleigh_beta > 0: K0 of C = alpha M + beta K0
  bool mass_ready_ = false;

  // mass scaling, lumping and the stable step
  mutable double stable_step_ = -1.0;           // cached stable_time_step()
  mutable std::vector<double> element_omega2_;  // element_frequencies_squared()
  std::vector<double> mass_scale_;              // per element s_e (empty: no mass scaling)
  mutable std::vector<double> element_length0_;  // element_time_step(): lengths at rest
  double element_time_step(std::size_t element) const;  // at its present shape
  std::vector<double> element_mass_;            // per element rho V (with mass scaling)
  // lumped mass: each element's nodal masses as assembled (element e's from
  // element_lumped_[element_lumped_start_[e]]; an eroded element's are stale and not read)
  std::vector<double> element_lumped_;
  std::vector<std::size_t> element_lumped_start_;

  // loads
  std::vector<Eigen::VectorXd> load_vectors_;  // per model load, at unit amplitude
  mutable std::map<std::string, FaceLoadOperator> face_operators_;
  std::map<std::string, MatrixX3> face_tractions_;
  std::vector<std::size_t> nodal_force_nodes_;
  MatrixX3 nodal_forces_;
  Eigen::VectorXd coupling_force_;

  // state, the operator and the integrators
  std::size_t steps_ = 0;
  Kinematics kin_;
  std::unique_ptr<InternalForceOperator> operator_;
  NonlinearOperator* nonlinear_ = nullptr;  // operator_ on the nonlinear path
  LinearContributionOperator* linear_sum_ = nullptr;  // operator_: linear path + contributions
  StaticIntegrator static_;
  NewmarkIntegrator newmark_;
  CentralDifferenceIntegrator central_;
  bool acceleration_valid_ = false;
  bool last_was_static_ = false;  // newton_iterations(): of solve_static() or of step()

  SolverTimings timings_;
  // node_detached(): each node's elements (built at the first call)
  mutable std::vector<std::size_t> node_element_offset_, node_elements_;
};

}  // namespace partita::fem
