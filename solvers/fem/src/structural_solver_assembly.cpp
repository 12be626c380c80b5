// StructuralSolver: the dof partition and the assembly of K, M and the model's load vectors.
#include <algorithm>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "parallel_loop.hpp"
#include "partita/fem/block_assembler.hpp"
#include "partita/fem/structural_solver.hpp"
#include "structural_solver_clock.hpp"

namespace partita::fem {

using detail::Clock;
using detail::seconds_since;

namespace {
// A = sum_e A_e^T M_e A_e with M_e = element(e): the element matrices of a chunk computed in
// parallel (each into its own slot), then added serially in element order, so A is the same,
// bit for bit, on any number of threads. An exception of an element (a degenerate element) is
// the one of the first element that threw, as in a serial loop. The additions are shared by
// column ranges, each entry's in element order.
template <class ElementFunction>
void assemble_elements(const Mesh& mesh, const BlockAssembler& assembler, SparseMatrix& a,
                       ElementFunction element) {
  constexpr std::size_t kChunk = 512;
  const auto& elements = mesh.elements();
  const std::size_t ne = elements.size();
  std::vector<ElementMatrix> chunk(std::min(ne, kChunk));
  for (std::size_t c0 = 0; c0 < ne; c0 += kChunk) {
    const long n = static_cast<long>(std::min(ne - c0, kChunk));
    detail::parallel_for_first_error(n, 64, [&](long i) {
      element(elements[c0 + static_cast<std::size_t>(i)], chunk[static_cast<std::size_t>(i)]);
    });
    // each thread adds into the columns of its own range of nodes, the elements in order
#pragma omp parallel if (n >= 64)
    {
      std::size_t part = 0, parts = 1;
#ifdef _OPENMP
      part = static_cast<std::size_t>(omp_get_thread_num());
      parts = static_cast<std::size_t>(omp_get_num_threads());
#endif
      const std::size_t nodes = assembler.num_nodes();
      const std::size_t first = nodes * part / parts, end = nodes * (part + 1) / parts;
      for (long i = 0; i < n; ++i)
        assembler.add_columns(a, elements[c0 + static_cast<std::size_t>(i)].node_span(),
                              chunk[static_cast<std::size_t>(i)], first, end);
    }
  }
}
}  // namespace

void StructuralSolver::setup_dofs() {
  std::vector<char> constrained(ndof_, 0);
  std::vector<SpaceTimeFunction> value(ndof_);
  for (const auto& bc : model_.dirichlet_conditions()) {
    for (auto node : mesh().node_set(bc.node_set)) {
      const std::size_t dof = 3 * node + static_cast<std::size_t>(bc.component);
      constrained[dof] = 1;
      value[dof] = bc.value;
    }
  }
  dofs_ = DofPartition(constrained);
  for (auto d : dofs_.constrained_dofs())
    constrained_value_.push_back(value[static_cast<std::size_t>(d)]);
}

void StructuralSolver::assemble_stiffness() {
  const auto t0 = Clock::now();
  const BlockAssembler assembler(mesh());
  k_ = assembler.make_matrix();
  std::vector<Matrix6> d;
  for (std::size_t r = 0; r < std::max<std::size_t>(1, mesh().region_names().size()); ++r) {
    d.push_back(model_.material(static_cast<int>(r)).elasticity_matrix());
  }
  // K = sum_e A_e^T K_e A_e
  assemble_elements(mesh(), assembler, k_, [&](const Element& e, ElementMatrix& m) {
    integrator_.stiffness(e.type, element_coordinates(mesh(), e),
                          d[static_cast<std::size_t>(e.region)], m);
  });
  timings_.assembly += seconds_since(t0);
}

void StructuralSolver::assemble_mass() {
  if (mass_ready_) return;
  const auto t0 = Clock::now();
  if (options_.mass == MassType::Consistent) {
    const BlockAssembler assembler(mesh());
    m_ = assembler.make_matrix();
    // M = sum_e A_e^T M_e A_e
    assemble_elements(mesh(), assembler, m_, [&](const Element& e, ElementMatrix& m) {
      const auto ei = static_cast<std::size_t>(&e - mesh().elements().data());
      integrator_.consistent_mass(e.type, element_coordinates(mesh(), e), element_density(ei), m);
    });
  } else {
    Eigen::VectorXd diag = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(ndof_));
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
    // each element's nodal masses kept for region_energies() (a monitor every window)
    element_lumped_start_.resize(mesh().num_elements() + 1);
    element_lumped_start_[0] = 0;
    for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei)
      element_lumped_start_[ei + 1] = element_lumped_start_[ei] +
                                      static_cast<std::size_t>(node_count(mesh().elements()[ei].type));
    element_lumped_.assign(element_lumped_start_.back(), 0.0);
    for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
      const Element& e = mesh().elements()[ei];
      if (element_eroded(ei)) continue;  // erosion: the element's mass has left
      integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), element_density(ei), m);
      for (int a = 0; a < node_count(e.type); ++a) {
        diag.segment<3>(3 * static_cast<Eigen::Index>(e.nodes[a])).array() += m[a];
        element_lumped_[element_lumped_start_[ei] + static_cast<std::size_t>(a)] = m[a];
      }
    }
    m_.resize(diag.size(), diag.size());
    m_.reserve(Eigen::VectorXi::Ones(diag.size()));
    for (Eigen::Index i = 0; i < diag.size(); ++i) m_.insert(i, i) = diag[i];
    m_.makeCompressed();
  }
  dofs_.split(m_, m_ff_, m_fc_);
  mass_ready_ = true;
  timings_.assembly += seconds_since(t0);
}

void StructuralSolver::assemble_loads() {
  const auto t0 = Clock::now();
  const auto n = static_cast<Eigen::Index>(ndof_);
  for (const auto& load : model_.loads()) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    switch (load.kind) {
      case LoadKind::Pressure:
      case LoadKind::Traction: {
        // f_a = sum_q N_a(x_q) t_q w_q with t = -p n (pressure) or the given traction
        const auto qps = face_quadrature_points(load.target);
        const auto& op = face_operator(load.target);
        for (std::size_t k = 0; k < op.node.size(); ++k) {
          const auto& qp = qps[op.qp[k]];
          const Vec3 t =
              load.kind == LoadKind::Pressure ? Vec3(-load.pressure * qp.normal) : load.vector;
          f.segment<3>(3 * static_cast<Eigen::Index>(op.node[k])) += op.coefficient[k] * t;
        }
        break;
      }
      case LoadKind::NodalForce:
        for (auto node : mesh().node_set(load.target)) {
          f.segment<3>(3 * static_cast<Eigen::Index>(node)) += load.vector;
        }
        break;
      case LoadKind::Gravity: {
        ElementVector fe;
        for (const auto& e : mesh().elements()) {
          integrator_.body_force(e.type, element_coordinates(mesh(), e),
                                 model_.density(e.region) * load.vector, fe);
          for (int a = 0; a < node_count(e.type); ++a) {
            f.segment<3>(3 * static_cast<Eigen::Index>(e.nodes[a])) += fe.segment<3>(3 * a);
          }
        }
        break;
      }
    }
    load_vectors_.push_back(std::move(f));
  }
  timings_.assembly += seconds_since(t0);
}

}  // namespace partita::fem
