// The FEM adapter proper: the Solver contract (meshes, read/write, advance, checkpoint, restart,
// output, the state check) over fem::StructuralSolver. Its schema: fem_schema.cpp; its building
// from the case: fem_build.cpp (the material: fem_material.cpp); its monitors: fem_monitors.cpp.

#include "fem_adapter.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "partita/fem/error.hpp"
#include "partita/fem/state_io.hpp"

#include "fem_output.hpp"
#include "fem_rupture.hpp"
#include "indenter_config.hpp"
#include "line_probe.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/output.hpp"

namespace partita::adapters {

// A solver error with the case file's keys named where the solver names a Newton option
// (the library speaks of NewtonOptions' members, which are the keys under analysis.nonlinear).
std::string FemAdapter::with_newton_keys(const std::string& what) {
  if (what.find("round_off_factor") == std::string::npos) return what;
  return what +
         " (keys analysis.nonlinear.force_tolerance and analysis.nonlinear.round_off_factor)";
}

std::size_t FemAdapter::find_interface(std::string_view mesh, Part* part) const {
  for (std::size_t k = 0; k < interfaces_.size(); ++k) {
    const auto& i = interfaces_[k];
    if (mesh == i.name || mesh == i.name + "_quadrature" || mesh == i.name + "_centres") {
      *part = mesh == i.name                ? Part::nodes
              : mesh == i.name + "_centres" ? Part::centres
                                            : Part::quadrature;
      return k;
    }
  }
  throw Error("fem '" + name_ + "' has no mesh '" + std::string(mesh) + "'");
}

// The interfaces' nodal forces go to the solver as one set (StructuralSolver::set_nodal_forces
// re-sums every coupling load over the whole force vector). read() only stores an interface's
// forces and marks them pending: with N interfaces and a read per interface per substep, applying
// at every read cost N^2 sums a substep (9 interfaces: 63 a window of 7 substeps, 7 % of the coarse
// double hull's run). They are applied once, before the step (and before anything that stores the
// solver's loads); the sum and its order are the same, so the results are bit for bit unchanged.
void FemAdapter::apply_nodal_forces() {
  if (!forces_pending_) return;
  forces_pending_ = false;
  std::size_t n = 0;
  for (const auto& i : interfaces_)
    if (i.has_forces) n += i.nodes.size();
  force_nodes_.clear();  // (work arrays: no allocation once they have grown)
  force_rows_.resize(static_cast<Eigen::Index>(n), 3);
  Eigen::Index row = 0;
  for (const auto& i : interfaces_) {
    if (!i.has_forces) continue;
    force_nodes_.insert(force_nodes_.end(), i.nodes.begin(), i.nodes.end());
    force_rows_.middleRows(row, i.nodal_forces.rows()) = i.nodal_forces;
    row += i.nodal_forces.rows();
  }
  solver_->set_nodal_forces(force_nodes_, force_rows_);
}

void FemAdapter::read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) {
  for (const auto& ind : indenters_) {
    if (!ind.has_surface || ind.name != mesh) continue;
    if (data != "force" || !ind.contact->indenter().is_free())
      throw Error("fem '" + name_ + "' reads only 'force' on indenter mesh '" + ind.name +
                  "', and only when the indenter is free (motion.mass)");
    // the resultant of the forces on the surface's vertices moves the rigid body
    ind.contact->set_external_force(values.colwise().sum().transpose());
    return;
  }
  Part part = Part::nodes;
  Interface& i = interfaces_[find_interface(mesh, &part)];
  if (part == Part::quadrature && data == "traction") {
    i.tractions = values;
    i.has_tractions = true;
    solver_->set_face_tractions_at_quadrature_points(i.face, i.tractions);
  } else if (part == Part::nodes && data == "force") {
    if (values.rows() != static_cast<Eigen::Index>(i.nodes.size()) || values.cols() != 3)
      throw Error("fem '" + name_ + "': 'force' on mesh '" + i.name + "' needs " +
                  std::to_string(i.nodes.size()) + " rows of 3, got " +
                  std::to_string(values.rows()) + " x " + std::to_string(values.cols()));
    if (!values.allFinite())
      throw Error("fem '" + name_ + "': non-finite 'force' on mesh '" + i.name + "'");
    i.nodal_forces = values;
    i.has_forces = true;
    forces_pending_ = true;  // applied before the step (apply_nodal_forces)
  } else {
    throw Error("fem '" + name_ + "' reads 'force' on mesh '" + i.name + "' and 'traction' on '" +
                i.name + "_quadrature', not '" + std::string(data) + "' on '" + std::string(mesh) +
                "'");
  }
}

void FemAdapter::write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) {
  for (const auto& ind : indenters_) {
    if (!ind.has_surface || ind.name != mesh) continue;
    if (data != "displacement")
      throw Error("fem '" + name_ + "' writes only 'displacement' on indenter mesh '" + ind.name + "'");
    // a translation: every vertex moves with the indenter
    for (const auto& m : meshes_)
      if (m.mesh.name() == ind.name)
        values = ind.contact->indenter().displacement().transpose().replicate(m.mesh.size(), 1);
    return;
  }
  Part part = Part::nodes;
  const Interface& i = interfaces_[find_interface(mesh, &part)];
  if (part == Part::centres && data == "attached") {
    // 1 while the element under the triangle is in the structure and its face is exposed (on
    // the boundary, or the element across eroded), 0 otherwise
    const std::size_t none = solver_->mesh().num_elements();
    values.resize(static_cast<Eigen::Index>(i.triangle_elements.size()), 1);
    for (std::size_t t = 0; t < i.triangle_elements.size(); ++t) {
      const std::size_t across = i.triangle_across[t];
      const bool exposed = across == none || solver_->element_eroded(across);
      values(static_cast<Eigen::Index>(t), 0) =
          exposed && !solver_->element_eroded(i.triangle_elements[t]) ? 1.0 : 0.0;
    }
    return;
  }
  if (part != Part::nodes || data != "displacement")
    throw Error("fem '" + name_ + "' writes 'displacement' on mesh '" + i.name +
                "' and 'attached' on '" + i.name + "_centres', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  values = solver_->displacements(i.nodes);
}

void FemAdapter::advance(double dt) {
  apply_nodal_forces();
  u_before_ = solver_->displacement();  // (no allocation after the first step: same size)
  try {
    if (transient_)
      solver_->step(dt);
    else
      solver_->step_static(dt);  // quasi-static: equilibrium with the loads at the new time
  } catch (const fem::Error& e) {
    throw Error("fem '" + name_ + "' at t = " + fmt::format("{:.6g}", solver_->time()) +
                " s: " + with_newton_keys(e.what()));
  }
  failure_log_.after_step(*solver_, name_);
  // the work of each interface's loads over this step: 1/2 (f_k + f_k+1) . du
  du_ = solver_->displacement() - u_before_;
  for (auto& i : interfaces_)
    i.audit.load_step(
        du_, i.has_tractions ? &i.tractions : nullptr,
        [&](const Eigen::MatrixX3d& t) { return solver_->face_traction_work(i.face, t, du_); },
        i.nodes, i.has_forces ? &i.nodal_forces : nullptr);
}

std::optional<double> FemAdapter::interface_work(std::string_view mesh) const {
  for (const auto& ind : indenters_)  // a free indenter: the work of the forces it read on it
    if (ind.has_surface && ind.name == mesh)
      return ind.contact->indenter().is_free() ? std::optional<double>(ind.contact->indenter().external_work())
                                               : std::nullopt;
  Part part = Part::nodes;
  return interfaces_[find_interface(mesh, &part)].audit.work();
}

double FemAdapter::stable_time_step() const {
  if (!transient_ || solver_->options().integrator != fem::Integrator::CentralDifference)
    return std::numeric_limits<double>::infinity();
  return stable_step_factor_ * solver_->stable_time_step();
}

void FemAdapter::save_checkpoint() {
  apply_nodal_forces();  // the state holds the loads read so far
  checkpoint_ = solver_->save_state();
  for (auto& i : interfaces_) {
    i.audit.save_checkpoint();
    i.nodal_forces_checkpoint = i.nodal_forces;
    i.tractions_checkpoint = i.tractions;
    i.has_forces_checkpoint = i.has_forces;
    i.has_tractions_checkpoint = i.has_tractions;
  }
  has_checkpoint_ = true;
}

void FemAdapter::restore_checkpoint() {
  if (!has_checkpoint_)
    throw Error("fem '" + name_ + "': restore_checkpoint() before save_checkpoint()");
  solver_->restore_state(checkpoint_);
  forces_pending_ = false;  // the checkpoint's loads hold until the next read
  failure_log_.restored(*solver_);
  for (auto& i : interfaces_) {  // and the values read then: the loads the restored solver holds
    i.audit.restore_checkpoint();
    i.nodal_forces = i.nodal_forces_checkpoint;
    i.tractions = i.tractions_checkpoint;
    i.has_forces = i.has_forces_checkpoint;
    i.has_tractions = i.has_tractions_checkpoint;
  }
}

std::string FemAdapter::check_state() const {
  const Eigen::VectorXd& u = solver_->displacement();
  if (!u.allFinite())
    return "the displacement has non-finite values: the structural step failed; check the "
           "loads, constraints (a free rigid-body motion) and the coupled forces";
  if (const double w = solver_->strain_energy(); !std::isfinite(w)) return non_finite_energy_report();
  const double d = solver_->max_displacement();
  if (d > model_size_)
    return fmt::format(
        "a node moved {:.3g} m, more than the model's size ({:.3g} m, the diagonal of its "
        "bounding box): the run is diverging or the structure is not held; check the "
        "constraints, loads and the coupled forces (an undamped soft plate: add analysis.rayleigh "
        "damping or a smaller time.window)",
        d, model_size_);
  return {};
}

// Where a non-finite stored energy comes from: the parts' elements (with the first element whose
// mean plastic strain is not finite, where the law has one) or an indenter's contact springs.
std::string FemAdapter::non_finite_energy_report() const {
  std::string where;
  const auto& regions = solver_->mesh().region_names();
  const fem::RegionEnergies e = solver_->region_energies();
  for (std::size_t r = 0; r < e.strain_energy.size(); ++r)
    if (!std::isfinite(e.strain_energy[r]))
      where += fmt::format("{}part '{}'", where.empty() ? "" : ", ",
                           regions.empty() ? std::string("all") : regions[r]);
  const Eigen::VectorXd eqps = solver_->element_equivalent_plastic_strain();
  for (Eigen::Index k = 0; k < eqps.size(); ++k) {
    if (std::isfinite(eqps[k])) continue;
    const auto el = static_cast<std::size_t>(k);
    fem::Vec3 c = fem::Vec3::Zero();
    const auto nodes = solver_->mesh().elements()[el].node_span();
    for (const auto n : nodes) c += solver_->mesh().node(n);
    c /= static_cast<double>(nodes.size());
    where += fmt::format("{}element {} at ({:.4g}, {:.4g}, {:.4g}) m{} has a non-finite plastic "
                         "strain",
                         where.empty() ? "" : "; ", el, c.x(), c.y(), c.z(),
                         solver_->element_failed(el) ? " (failed)" : "");
    break;
  }
  for (const auto& ind : indenters_)
    if (!std::isfinite(ind.contact->stored_energy()))
      where += fmt::format("{}the contact springs of indenter '{}'", where.empty() ? "" : "; ",
                           ind.contact->name());
  return fmt::format(
      "the stored (strain) energy is not finite at t = {:.6g} s (in {}): an element's state or a "
      "contact has diverged; reduce the time step (analysis.mass_scaling_time_step, "
      "time.window), or check the material and the contact's stiffness",
      solver_->time(), where.empty() ? "no part or indenter in particular" : where);
}

void FemAdapter::write_restart(BinaryWriter& out) const {
  out.section("fem");
  std::ostringstream state;
  fem::write_state(state, solver_->save_state());  // the solver's own versioned format
  out.bytes(state.str());
  out.section("fem interfaces");
  for (const auto& i : interfaces_) {
    out.write(i.nodal_forces);
    out.write(i.tractions);
    out.write(static_cast<std::uint8_t>(i.has_forces));
    out.write(static_cast<std::uint8_t>(i.has_tractions));
  }
  out.section("fem interface work");
  for (const auto& i : interfaces_) i.audit.save(out);
}

void FemAdapter::read_restart(BinaryReader& in) {
  in.expect_section("fem");
  std::istringstream bytes(in.bytes());
  fem::SolverState s;
  try {
    s = fem::read_state(bytes);
  } catch (const fem::Error& e) {
    throw Error(in.source() + ": the FE state of '" + name_ + "': " + e.what());
  }
  const Eigen::Index dofs = solver_->displacement().size();
  for (const Eigen::VectorXd* v : {&s.displacement, &s.velocity, &s.acceleration})
    if (v->size() != dofs) in.fail(std::to_string(dofs) + " degrees of freedom (the same mesh)");
  in.expect_section("fem interfaces");
  for (auto& i : interfaces_) {
    in.read(i.nodal_forces);
    in.read(i.tractions);
    i.has_forces = in.get<std::uint8_t>() != 0;
    i.has_tractions = in.get<std::uint8_t>() != 0;
  }
  in.expect_section("fem interface work");
  for (auto& i : interfaces_) i.audit.load(in, "loads of interface '" + i.name + "'");
  solver_->restore_state(s);
  forces_pending_ = false;
  failure_log_.restored(*solver_);
}

void FemAdapter::write_output(const OutputFrame& frame) {
  const std::string file = fmt::format("{}_fem_{:06d}.vtu", frame.prefix, frame.index);
  std::vector<const fem::IndenterContact*> contacts;
  for (const auto& ind : indenters_) contacts.push_back(ind.contact);
  write_fem_vtu(*solver_, frame.vtk_directory / file, frame.vtk, contacts);
  files_ = {{"fem", file}};
  for (const auto& ind : indenters_) {  // the indenters' surfaces where they are
    if (!ind.has_surface) continue;
    const std::string f = fmt::format("{}_{}_{:06d}.vtp", frame.prefix, ind.name, frame.index);
    for (const auto& m : meshes_)
      if (m.mesh.name() == ind.name) write_indenter_vtp(frame.vtk_directory / f, m, *ind.contact, frame.vtk);
    files_.emplace_back(ind.name, f);
  }
  for (const auto& p : probes_)
    write_file_atomically(frame.vtk_directory.parent_path() / "probes" /
                              fmt::format("{}_{}_{:06d}.csv", frame.prefix, p.name(), frame.index),
                          p.csv(*solver_));
}

}  // namespace partita::adapters
