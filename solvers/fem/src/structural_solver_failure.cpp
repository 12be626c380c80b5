// StructuralSolver: rupture (failure criterion, erosion) and energies by region.
#include <algorithm>
#include <limits>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem {

void StructuralSolver::validate_failure_setup() const {
  const std::size_t regions = std::max<std::size_t>(1, mesh().region_names().size());
  bool erosion = false;
  for (std::size_t r = 0; r < regions; ++r) {
    const FailureCriterion& c = model_.failure_criterion(static_cast<int>(r));
    if (!c.active()) continue;
    const std::string name = mesh().region_names().empty() ? "all" : mesh().region_names()[r];
    if (model_.material_law(static_cast<int>(r)) == nullptr) {
      throw Error("region '" + name +
                  "': a failure criterion needs a law with plastic strain (j2-plasticity); a "
                  "linear-elastic region would never fail");
    }
    erosion = erosion || c.erosion;
  }
  if (!erosion) return;
  if (options_.integrator != Integrator::CentralDifference) {
    throw Error(
        "element erosion works in central-difference (explicit) analyses only: the static and "
        "Newmark solvers would have to factorise a tangent whose eroded parts may float free; "
        "use the central-difference integrator, or turn erosion off (failures are still "
        "reported)");
  }
  if (options_.rayleigh_beta != 0.0) {
    throw Error(
        "element erosion with stiffness-proportional damping (rayleigh beta > 0): the damping "
        "matrix beta K0 would keep the eroded elements' stiffness; use mass-proportional damping "
        "(alpha) or turn erosion off");
  }
}

void StructuralSolver::update_failures() {
  if (nonlinear_ == nullptr) return;
  MaterialContribution& material = nonlinear_->material();
  if (!material.has_failure_criteria()) return;
  const std::vector<std::size_t> failed = material.update_failures(kin_.time);
  if (!material.erosion() ||
      std::none_of(failed.begin(), failed.end(), [&](auto e) { return material.eroded(e); }))
    return;
  // Erosion: the lumped mass without the eroded elements; the kinetic energy that leaves with
  // their mass, E_k(M_before) - E_k(M_after), joins the eroded energy. Nodes that no element
  // holds any more stop (mass 0: their velocity is set to zero, see the integrator).
  const double kinetic_before = kinetic_energy();
  mass_ready_ = false;
  assemble_mass();
  central_.invalidate_mass();
  for (std::size_t d = 0; d < ndof_; ++d) {
    const auto i = static_cast<Eigen::Index>(d);
    if (!(m_.coeff(i, i) > 0.0)) kin_.v[i] = kin_.a[i] = 0.0;
  }
  material.add_eroded_energy(kinetic_before - kinetic_energy());
  // f_int and the stored energy without the eroded elements (reactions, energy balance)
  refresh_internal_force();
}

std::size_t StructuralSolver::failed_elements() const {
  return nonlinear_ != nullptr ? nonlinear_->material().num_failed() : 0;
}

bool StructuralSolver::element_failed(std::size_t element) const {
  return nonlinear_ != nullptr && nonlinear_->material().has_failure_criteria() &&
         nonlinear_->material().failed(element);
}

bool StructuralSolver::element_eroded(std::size_t element) const {
  return nonlinear_ != nullptr && nonlinear_->material().has_failure_criteria() &&
         nonlinear_->material().eroded(element);
}

double StructuralSolver::element_failure_time(std::size_t element) const {
  if (!element_failed(element)) return -1.0;
  return nonlinear_->material().failure_time(element);
}

double StructuralSolver::element_damage(std::size_t element) const {
  if (nonlinear_ == nullptr || !nonlinear_->material().has_failure_criteria()) return -1.0;
  return nonlinear_->material().element_damage(element);
}

bool StructuralSolver::node_detached(std::size_t node) const {
  if (nonlinear_ == nullptr || !nonlinear_->material().has_failure_criteria()) return false;
  const Mesh& mesh = model_.mesh();
  if (node_element_offset_.empty()) {
    std::vector<std::size_t> count(mesh.num_nodes() + 1, 0);
    for (const auto& el : mesh.elements())
      for (int a = 0; a < node_count(el.type); ++a) ++count[el.nodes[a] + 1];
    for (std::size_t n = 0; n < mesh.num_nodes(); ++n) count[n + 1] += count[n];
    node_element_offset_ = count;
    node_elements_.assign(count.back(), 0);
    for (std::size_t e = 0; e < mesh.num_elements(); ++e) {
      const Element& el = mesh.elements()[e];
      for (int a = 0; a < node_count(el.type); ++a) node_elements_[count[el.nodes[a]]++] = e;
    }
  }
  const std::size_t from = node_element_offset_[node], to = node_element_offset_[node + 1];
  if (from == to) return false;
  for (std::size_t i = from; i < to; ++i)
    if (!element_eroded(node_elements_[i])) return false;
  return true;
}

std::optional<FailureEvent> StructuralSolver::first_failure() const {
  if (nonlinear_ == nullptr || !nonlinear_->material().has_failure_criteria()) return {};
  const MaterialContribution& material = nonlinear_->material();
  std::optional<FailureEvent> first;
  for (std::size_t e = 0; e < mesh().num_elements(); ++e) {
    if (!material.failed(e)) continue;
    if (first && !(material.failure_time(e) < first->time)) continue;
    const Element& el = mesh().elements()[e];
    FailureEvent f;
    f.element = e;
    f.region = mesh().region_names().empty()
                   ? "all"
                   : mesh().region_names()[static_cast<std::size_t>(el.region)];
    for (auto n : el.node_span()) f.centroid += mesh().node(n);
    f.centroid /= static_cast<double>(el.node_span().size());
    f.time = material.failure_time(e);
    f.plastic_strain = material.element_plastic_strain(e);
    f.failure_strain = material.failure_strain(e);
    f.damage = material.element_damage(e);
    first = f;
  }
  return first;
}

double StructuralSolver::eroded_energy() const {
  return nonlinear_ != nullptr ? nonlinear_->material().eroded_energy() : 0.0;
}

double StructuralSolver::max_equivalent_plastic_strain() const {
  if (nonlinear_ == nullptr || nonlinear_->equivalent_plastic_strain().size() == 0) return 0.0;
  return nonlinear_->equivalent_plastic_strain().maxCoeff();
}

RegionEnergies StructuralSolver::region_energies() const {
  const std::size_t regions = std::max<std::size_t>(1, mesh().region_names().size());
  RegionEnergies out;
  out.plastic_work.assign(regions, 0.0);
  out.strain_energy.assign(regions, 0.0);
  out.kinetic_energy.assign(regions, 0.0);
  ElementMatrix m_e, k_e;
  ElementVector v_e, u_e;
  for (std::size_t e = 0; e < mesh().num_elements(); ++e) {
    const Element& el = mesh().elements()[e];
    const auto r = static_cast<std::size_t>(el.region);
    const int nn = node_count(el.type);
    v_e.resize(3 * nn);
    u_e.resize(3 * nn);
    for (int a = 0; a < nn; ++a) {
      v_e.segment<3>(3 * a) = kin_.v.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a]));
      u_e.segment<3>(3 * a) = kin_.u.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a]));
    }
    if (nonlinear_ != nullptr) {
      out.strain_energy[r] += nonlinear_->material().element_strain_energy()[e];
      if (!element_eroded(e)) out.plastic_work[r] += nonlinear_->material().element_plastic_work(e);
    } else {
      // 1/2 u_e^T K_e u_e
      integrator_.stiffness(el.type, element_coordinates(mesh(), el),
                            model_.material(el.region).elasticity_matrix(), k_e);
      out.strain_energy[r] += 0.5 * u_e.dot(k_e * u_e);
    }
    if (!mass_ready_ || element_eroded(e)) continue;
    // 1/2 v_e^T M_e v_e (its share of the assembled mass)
    if (options_.mass == MassType::Lumped) {
      // the nodal masses assemble_mass() built (the same numbers, not recomputed each window)
      const double* m_lumped = element_lumped_.data() + element_lumped_start_[e];
      for (int a = 0; a < nn; ++a)
        out.kinetic_energy[r] += 0.5 * m_lumped[a] * v_e.segment<3>(3 * a).squaredNorm();
    } else {
      integrator_.consistent_mass(el.type, element_coordinates(mesh(), el), element_density(e),
                                  m_e);
      out.kinetic_energy[r] += 0.5 * v_e.dot(m_e * v_e);
    }
  }
  return out;
}

}  // namespace partita::fem
