#pragma once
// Adapter of the native FEM solver (solvers/fem) to the Solver contract.
//
// YAML (see spec() or `partita docs fem`): mesh (structured box or Gmsh file), material
// (model: linear-elastic | neo-hooke | j2-plasticity), constraints, loads, interfaces, analysis
// (static or transient; integrator: newmark | central-difference; nonlinear: Newton options).
//
// For each interface {name: N, face: F} it exposes two meshes:
//   N             the face's nodes (with the face triangulated): writes "displacement" [m],
//                 reads "force" [N] (nodal forces: the conservative coupling input)
//   N_quadrature  the face's surface quadrature points: reads "traction" [Pa] (the seed's
//                 route: tractions at the quadrature points, integrated with the face rule)
//   N_centres     the centroids of the triangles of N, in their order: writes "attached" [-],
//                 1 while the element under the triangle is in the structure, 0 once it is
//                 eroded (a DEM that took N as a wall reads it on its N_centres and drops the
//                 triangle from its contacts: granules pass where the hull has ruptured)
// Monitors: N.force_x|y|z (total interface force received [N]), static_reaction_z (the force the
// interfaces must carry for static equilibrium: minus the sum of the applied loads, gravity
// included [N]), max_displacement [m], kinetic_energy, strain_energy, plastic_work,
// external_work, damping_work, energy_balance (external + indenters' work - strain - kinetic -
// plastic - damping - eroded) [J]; rupture and energies by part: see fem_rupture.hpp; each rigid
// indenter's quantities (indenter_config.hpp). A bounded indenter (sphere, capsule, surface) also
// offers its surface as the mesh <name>, which writes "displacement" (its translation at every
// vertex): a DEM takes it with `from: <fem>.<name>`.

#include <memory>
#include <string>
#include <vector>

#include "fem_rupture.hpp"
#include "line_probe.hpp"
#include "partita/fem/fem.hpp"
#include "mesh_locator.hpp"
#include "partita/interface/interface_work.hpp"
#include "partita/interface/monitor_table.hpp"
#include "partita/interface/solver.hpp"

namespace partita::adapters {

class FemAdapter : public Solver {
 public:
  FemAdapter(const SolverContext& context);

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override;
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override;
  double stable_time_step() const override;
  void advance(double dt) override;
  double time() const override { return solver_->time(); }
  void save_checkpoint() override;
  void restore_checkpoint() override;
  void write_output(const OutputFrame& frame) override;
  std::vector<std::pair<std::string, std::string>> output_files() const override { return files_; }
  std::string check_state() const override;
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override;
  void read_restart(BinaryReader& in) override;
  std::vector<MonitorValue> monitors() const override;
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override;
  std::optional<double> interface_work(std::string_view mesh) const override;

  /// The participant's keys (fem_schema.cpp); the adapter is built from them (fem_build.cpp).
  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Solver> create(const SolverContext& context);
  /// The names of the components, as constraints and loads spell them.
  static inline const std::vector<std::string> kComponents = {"x", "y", "z"};
  /// The monitor quantities: their docs (registration) and values (fem_monitors.cpp).
  static const MonitorTable<FemAdapter>& monitor_table();

 private:
  struct Interface {
    std::string name;
    std::string face;
    std::vector<std::size_t> nodes;  // global node ids of the face mesh
    std::vector<double> qp_weights;  // area of each quadrature point [m^2]
    std::vector<std::size_t> triangle_elements;  // the volume element under each triangle
    // the element across each triangle's face (num_elements(): none, a face of the boundary):
    // the triangle is attached while its element is in and the one across is not
    std::vector<std::size_t> triangle_across;
    Eigen::MatrixX3d nodal_forces;   // last "force" read
    Eigen::MatrixX3d tractions;      // last "traction" read
    bool has_forces = false;
    bool has_tractions = false;
    // The interface energy audit (Solver::interface_work): the work of the received loads on the
    // displacements since t = 0 (the trapezoidal rule of Newmark's energy balance).
    InterfaceWork audit = InterfaceWork::loads();
    // What was read when the checkpoint was saved: a restore brings back the solver's loads and
    // these with them (the audit and the force monitors read them until the next read).
    Eigen::MatrixX3d nodal_forces_checkpoint, tractions_checkpoint;
    bool has_forces_checkpoint = false;
    bool has_tractions_checkpoint = false;
  };
  /// A solver error with the case file's keys named where the solver names a Newton option.
  static std::string with_newton_keys(const std::string& what);
  enum class Part { nodes, quadrature, centres };  // the meshes N, N_quadrature, N_centres
  /// Index into interfaces_ of the coupling mesh `mesh` (and which of its meshes); throws if
  /// unknown.
  std::size_t find_interface(std::string_view mesh, Part* part) const;
  /// Hands the interfaces' nodal forces to the solver if a read changed them since (see the .cpp).
  void apply_nodal_forces();

  std::string name_;
  bool transient_ = true;
  double stable_step_factor_ = 0.9;
  std::unique_ptr<fem::StructuralSolver> solver_;
  fem::SolverState checkpoint_;
  bool has_checkpoint_ = false;
  std::vector<Interface> interfaces_;
  bool forces_pending_ = false;          // a "force" read not yet handed to the solver
  std::vector<std::size_t> force_nodes_;  // work arrays of apply_nodal_forces
  fem::MatrixX3 force_rows_;
  Eigen::VectorXd u_before_, du_;  // displacement before a step and its increment (work arrays)
  std::vector<InterfaceMesh> meshes_;
  std::vector<std::pair<std::string, std::string>> files_;
  Eigen::Vector3d applied_per_unit_ = Eigen::Vector3d::Zero();
  double model_size_ = 0.0;
  std::vector<LineProbe> probes_;  // diagonal of the mesh's bounding box [m]
  // point monitors (points:): where each lies in the mesh
  struct PointMonitor {
    std::string name;
    MeshLocation at;
  };
  std::unique_ptr<MeshLocator> locator_;  // only with point monitors
  std::vector<PointMonitor> points_;
  FailureLog failure_log_;  // logs the first failed element
  // rigid indenters (indenters:, see indenter_config.hpp); the solver owns the contacts
  std::string non_finite_energy_report() const;
  struct Indenter {
    std::string name;
    Eigen::Vector3d reference;  // its `position`: the monitors' N.x, N.y, N.z at rest
    fem::IndenterContact* contact = nullptr;
    bool has_surface = false;  // offers the mesh <name> (writes "displacement")
  };
  std::vector<Indenter> indenters_;
  fem::SelfContact* self_contact_ = nullptr;  // self_contact: (the solver owns it)
};

}  // namespace partita::adapters
