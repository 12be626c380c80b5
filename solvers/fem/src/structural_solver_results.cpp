// StructuralSolver: results (displacements, reactions, stresses) and the scalar monitors
// (energies, Newton iterations, plastic strain, totals).
#include <algorithm>
#include <cmath>

#include "parallel_loop.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem {

MatrixX3 StructuralSolver::displacements(const std::vector<std::size_t>& nodes) const {
  MatrixX3 d(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t k = 0; k < nodes.size(); ++k)
    d.row(static_cast<Eigen::Index>(k)) = displacement(nodes.at(k)).transpose();
  return d;
}

Vec3 StructuralSolver::reaction(const std::string& node_set) const {
  const auto& nodes = mesh().node_set(node_set);
  // r = K u + C v + M a - F  (nonlinear or explicit: f_int(u) for K u)
  Eigen::VectorXd r =
      (uses_newton() || options_.integrator == Integrator::CentralDifference)
          ? Eigen::VectorXd(kin_.f_int - kin_.f)
          : Eigen::VectorXd(k_ * kin_.u - kin_.f);
  if (mass_ready_) {
    r += m_ * kin_.a;
    add_damping_force(kin_.v, 1.0, r);
  }
  Vec3 sum = Vec3::Zero();
  for (auto n : nodes) sum += r.segment<3>(3 * static_cast<Eigen::Index>(n));
  return sum;
}

MatrixX6 StructuralSolver::nodal_stress() const {
  MatrixX6 s = MatrixX6::Zero(static_cast<Eigen::Index>(mesh().num_nodes()), 6);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(s.rows());
  if (nonlinear_ != nullptr) {
    // nonlinear path: each element's mean Cauchy stress over its quadrature points, averaged
    // over the elements that share a node
    const auto& offsets = nonlinear_->element_qp_offsets();
    const auto& sigma = nonlinear_->cauchy_stress();
    for (std::size_t e = 0; e < mesh().num_elements(); ++e) {
      const auto q0 = static_cast<Eigen::Index>(offsets[e]);
      const auto nq = static_cast<Eigen::Index>(offsets[e + 1] - offsets[e]);
      const Eigen::Matrix<double, 1, 6> mean = sigma.middleRows(q0, nq).colwise().mean();
      for (auto node : mesh().elements()[e].node_span()) {
        s.row(static_cast<Eigen::Index>(node)) += mean;
        count[static_cast<Eigen::Index>(node)] += 1.0;
      }
    }
    for (Eigen::Index i = 0; i < s.rows(); ++i) {
      if (count[i] > 0) s.row(i) /= count[i];
    }
    return s;
  }
  // Linear path: the elements' nodal stresses, chunk by chunk on the threads (each element's
  // into a slot of its own), then added to the nodes in element order (the same sums on any
  // number of threads). (105,800 Hex8 with incompatible modes: about 1 s on one thread, which was
  // most of the scale case's VTK output.)
  // Small meshes stay on one thread: a frame of the steel case's 800 elements takes a few ms, and
  // waking the threads for it left them spinning into the next steps (its plate took 6 % longer).
  constexpr std::size_t kChunk = 1024;
  const auto& elements = mesh().elements();
  const std::size_t ne = elements.size();
  const long min_parallel = ne >= 4 * kChunk ? 64 : static_cast<long>(kChunk) + 1;
  std::vector<ElementStresses> chunk(std::min(ne, kChunk));
  for (std::size_t c0 = 0; c0 < ne; c0 += kChunk) {
    const long n = static_cast<long>(std::min(ne - c0, kChunk));
    detail::parallel_for_first_error(n, min_parallel, [&](long k) {
      const Element& e = elements[c0 + static_cast<std::size_t>(k)];
      const int nn = node_count(e.type);
      ElementVector ue(3 * nn);
      for (int a = 0; a < nn; ++a)
        ue.segment<3>(3 * a) = kin_.u.segment<3>(3 * static_cast<Eigen::Index>(e.nodes[a]));
      integrator_.stresses_at_nodes(e.type, element_coordinates(mesh(), e),
                                    model_.material(e.region).elasticity_matrix(), ue,
                                    chunk[static_cast<std::size_t>(k)]);
    });
    for (long k = 0; k < n; ++k) {
      const Element& e = elements[c0 + static_cast<std::size_t>(k)];
      const ElementStresses& se = chunk[static_cast<std::size_t>(k)];
      for (int a = 0; a < node_count(e.type); ++a) {
        const auto i = static_cast<Eigen::Index>(e.nodes[a]);
        s.row(i) += se.row(a);
        count[i] += 1.0;
      }
    }
  }
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    if (count[i] > 0) s.row(i) /= count[i];
  }
  return s;
}

Eigen::VectorXd StructuralSolver::von_mises(const MatrixX6& s) {
  Eigen::VectorXd vm(s.rows());
  // sigma_vm = sqrt(1/2 ((sx-sy)^2 + (sy-sz)^2 + (sz-sx)^2) + 3 (txy^2 + tyz^2 + tzx^2))
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    const double a = s(i, 0) - s(i, 1), b = s(i, 1) - s(i, 2), c = s(i, 2) - s(i, 0);
    vm[i] = std::sqrt(0.5 * (a * a + b * b + c * c) +
                      3.0 * (s(i, 3) * s(i, 3) + s(i, 4) * s(i, 4) + s(i, 5) * s(i, 5)));
  }
  return vm;
}

double StructuralSolver::kinetic_energy() const {
  return mass_ready_ ? 0.5 * kin_.v.dot(m_ * kin_.v) : 0.0;
}
double StructuralSolver::strain_energy() const {
  if (nonlinear_ != nullptr) return nonlinear_->strain_energy();
  // 1/2 u.K u plus the contributions' stored energy, at the last evaluation (kin_.u)
  if (linear_sum_ != nullptr) return linear_sum_->strain_energy();
  return 0.5 * kin_.u.dot(k_ * kin_.u);
}

double StructuralSolver::plastic_work() const {
  return operator_->plastic_work();
}

double StructuralSolver::enhanced_strain_work() const {
  return nonlinear_ != nullptr ? nonlinear_->material().enhanced_strain_work() : 0.0;
}

double StructuralSolver::energy_balance() const {
  // W_ext - (W_strain + E_kin + W_plastic + W_damping + W_eroded + W_beta)
  return external_work() - (strain_energy() + kinetic_energy() + plastic_work() + damping_work() +
                            eroded_energy() + enhanced_strain_work());
}

int StructuralSolver::newton_iterations() const {
  if (!uses_newton()) return 0;
  if (last_was_static_) {
    int n = 0;
    for (const auto& r : static_.reports()) n += r.iterations;
    return n;
  }
  return options_.integrator == Integrator::Newmark ? newmark_.step_iterations() : 0;
}

Eigen::VectorXd StructuralSolver::equivalent_plastic_strain() const {
  return nonlinear_ != nullptr ? nonlinear_->equivalent_plastic_strain() : Eigen::VectorXd();
}

Eigen::VectorXd StructuralSolver::element_equivalent_plastic_strain() const {
  if (nonlinear_ == nullptr) return {};
  const auto& offsets = nonlinear_->element_qp_offsets();
  const Eigen::VectorXd& q = nonlinear_->equivalent_plastic_strain();
  Eigen::VectorXd out(static_cast<Eigen::Index>(mesh().num_elements()));
  for (std::size_t e = 0; e < mesh().num_elements(); ++e) {
    const auto q0 = static_cast<Eigen::Index>(offsets[e]);
    out[static_cast<Eigen::Index>(e)] =
        q.segment(q0, static_cast<Eigen::Index>(offsets[e + 1] - offsets[e])).mean();
  }
  return out;
}

double StructuralSolver::max_displacement() const {
  // sqrt is monotone and correctly rounded: the root of the largest squared length is the
  // largest length, bit for bit, with one square root instead of one per node
  double m = 0.0;
  for (Eigen::Index i = 0; i + 2 < kin_.u.size(); i += 3)
    m = std::max(m, kin_.u.segment<3>(i).squaredNorm());
  return std::sqrt(m);
}

Vec3 StructuralSolver::total_coupling_force() const {
  return coupling_force_.reshaped(3, coupling_force_.size() / 3).rowwise().sum();
}

Vec3 StructuralSolver::total_external_force() const {
  return kin_.f.reshaped(3, kin_.f.size() / 3).rowwise().sum();
}

}  // namespace partita::fem
