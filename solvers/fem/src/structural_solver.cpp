#include "partita/fem/structural_solver.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "parallel_loop.hpp"
#include "partita/fem/block_assembler.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/linear_contribution_operator.hpp"
#include "partita/fem/linear_elastic_operator.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"

namespace partita::fem {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double amplitude_at(const TimeFunction& f, double t) {
  return f ? f(t) : 1.0;
}

}  // namespace

StructuralSolver::StructuralSolver(Model model, SolverOptions options)
    : model_(std::move(model)),
      options_(options),
      integrator_(model_.hex8_formulation()),
      static_(options_.newton, options_.linear_solver, options_.fill_ordering,
              options_.factor_threading),
      newmark_(options_.newmark_beta, options_.newmark_gamma, options_.newton,
               options_.linear_solver, options_.fill_ordering, options_.factor_threading) {
  newmark_.set_solve_threading(options_.solve_threading);
  newmark_.set_timings(&timings_);
  {
    // the static runaway test (a limit load where Newton keeps converging): the model's size
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t n = 0; n < model_.mesh().num_nodes(); ++n) {
      lo = lo.cwiseMin(model_.mesh().node(n));
      hi = hi.cwiseMax(model_.mesh().node(n));
    }
    if (model_.mesh().num_nodes() > 0) static_.set_model_size((hi - lo).norm());
  }
  if (!(options_.newmark_beta > 0.0) || !(options_.newmark_gamma > 0.0)) {
    throw Error("Newmark parameters must be > 0 (beta = 1/4, gamma = 1/2 is the default)");
  }
  if (options_.rayleigh_alpha < 0.0 || options_.rayleigh_beta < 0.0) {
    throw Error("Rayleigh damping coefficients must be >= 0");
  }
  if (resolve(options_.linear_solver) == LinearSolver::Cholmod && !cholmod_available()) {
    throw Error(
        "linear solver 'cholmod': this build of partita has no CHOLMOD (configure with "
        "libsuitesparse-dev installed and -DPARTITA_CHOLMOD=ON); use 'eigen-ldlt' or 'auto'");
  }
  if (options_.integrator == Integrator::CentralDifference && options_.mass != MassType::Lumped) {
    throw Error("the central-difference integrator needs a lumped mass (mass: lumped)");
  }
  if (model_.hex8_formulation() == Hex8Formulation::Reduced) {
    if (options_.integrator != Integrator::CentralDifference)
      throw Error(
          "the reduced Hex8 (hex8: reduced) is an element of central-difference analyses (its "
          "internal force has no tangent); static and Newmark analyses use the EAS Hex8 "
          "(hex8: incompatible-modes)");
    if (options_.rayleigh_beta != 0.0)
      throw Error(
          "the reduced Hex8 (hex8: reduced) has no tangent for the stiffness-proportional "
          "Rayleigh damping's K0: use mass-proportional damping (rayleigh.alpha) with it");
    // the element exists on the nonlinear path (element by element, LinearElasticLaw where the
    // model is linear elastic)
    options_.nonlinear_path = true;
  }
  if (model_.is_linear() && model_.hex8_formulation() == Hex8Formulation::FBar) {
    throw Error(
        "the F-bar Hex8 is an element of the nonlinear path (neo-hooke, j2-plasticity, ...); a "
        "linear-elastic model uses the incompatible-mode Hex8, which does not lock");
  }
  ndof_ = 3 * mesh().num_nodes();
  const auto n = static_cast<Eigen::Index>(ndof_);
  kin_.u = Eigen::VectorXd::Zero(n);
  kin_.v = Eigen::VectorXd::Zero(n);
  kin_.a = Eigen::VectorXd::Zero(n);
  kin_.f = Eigen::VectorXd::Zero(n);
  kin_.f_int = Eigen::VectorXd::Zero(n);
  coupling_force_ = Eigen::VectorXd::Zero(n);
  setup_dofs();
  if (model_.is_linear() && !options_.nonlinear_path) {
    validate_failure_setup();
    assemble_stiffness();
    operator_ = std::make_unique<LinearElasticOperator>(k_);
  } else {
    const auto t0 = Clock::now();
    auto op = std::make_unique<NonlinearOperator>(model_);
    nonlinear_ = op.get();
    operator_ = std::move(op);
    validate_failure_setup();
    if (options_.rayleigh_beta != 0.0) {
      // K0 = K_t(u = 0) with the initial history, symmetrised: the damping stiffness
      Eigen::VectorXd f0;
      operator_->evaluate(Eigen::VectorXd::Zero(n), f0, &k0_);
      k0_ = 0.5 * (SparseMatrix(k0_.transpose()) + k0_);
    }
    timings_.assembly += seconds_since(t0);
  }
  assemble_loads();
  // Start from rest with the prescribed values of t = 0.
  Eigen::VectorXd uc;
  prescribed_values(0.0, uc);
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k)
    kin_.u[dofs_.constrained_dofs()[k]] = uc[static_cast<Eigen::Index>(k)];
  evaluate_external_force(0.0, kin_.f);
  setup_mass_scaling();
  if (nonlinear_ != nullptr || options_.integrator == Integrator::CentralDifference) {
    refresh_internal_force();
  }
}

StructuralSolver::~StructuralSolver() = default;

void StructuralSolver::add_contribution(std::unique_ptr<OperatorContribution> contribution) {
  if (nonlinear_ != nullptr) {
    nonlinear_->add_contribution(std::move(contribution));
  } else if (options_.integrator == Integrator::CentralDifference) {
    // the linear path's explicit steps: K u (one sparse product) plus the contributions
    if (linear_sum_ == nullptr) {
      auto op = std::make_unique<LinearContributionOperator>(k_, mesh());
      linear_sum_ = op.get();
      operator_ = std::move(op);
    }
    linear_sum_->add_contribution(std::move(contribution));
  } else {
    throw Error(
        "operator contributions on a linear-elastic model need central difference, or the "
        "nonlinear path (SolverOptions::nonlinear_path, or a material law) for static and "
        "Newmark analyses: the linear path factorises K once");
  }
  stable_step_ = -1.0;  // the contribution may lower it
  refresh_internal_force();
  acceleration_valid_ = false;
}

// ---------------------------------------------------------------- setup and assembly

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
  dofs_.split(k_, k_ff_, k_fc_);
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

// ---------------------------------------------------------------- faces and coupling loads

std::vector<FaceQuadraturePoint> StructuralSolver::face_quadrature_points(
    const std::string& face) const {
  std::vector<FaceQuadraturePoint> out;
  const auto& elements = mesh().face(face);
  FaceShapeVector n;
  FaceShapeGradient dn;
  for (std::size_t s = 0; s < elements.size(); ++s) {
    const auto& se = elements[s];
    const int nn = node_count(se.type);
    Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxFaceNodes, 3> x(nn, 3);
    for (int a = 0; a < nn; ++a) x.row(a) = mesh().node(se.nodes[a]).transpose();
    for (const auto& q : face_rule(se.type)) {
      shape_functions(se.type, q.xi, n, dn);
      // dA = |dx/dxi x dx/deta| dxi deta, outward normal along dx/dxi x dx/deta
      const Vec3 t1 = x.transpose() * dn.col(0);
      const Vec3 t2 = x.transpose() * dn.col(1);
      const Vec3 nv = t1.cross(t2);
      const double area = nv.norm();
      if (!(area > 0.0))
        throw Error("face '" + face + "': degenerate surface element " + std::to_string(s));
      out.push_back({x.transpose() * n, nv / area, q.weight * area, s});
    }
  }
  return out;
}

const StructuralSolver::FaceOperator& StructuralSolver::face_operator(
    const std::string& face) const {
  auto it = face_operators_.find(face);
  if (it != face_operators_.end()) return it->second;
  FaceOperator op;
  const auto qps = face_quadrature_points(face);
  const auto& elements = mesh().face(face);
  FaceShapeVector n;
  FaceShapeGradient dn;
  std::size_t q_index = 0;
  for (const auto& se : elements) {
    for (const auto& q : face_rule(se.type)) {
      shape_functions(se.type, q.xi, n, dn);
      for (int a = 0; a < node_count(se.type); ++a) {
        op.node.push_back(se.nodes[a]);
        op.qp.push_back(q_index);
        op.coefficient.push_back(n[a] * qps[q_index].weight);
      }
      ++q_index;
    }
  }
  op.num_qp = q_index;
  return face_operators_.emplace(face, std::move(op)).first->second;
}

FaceMesh StructuralSolver::face_mesh(const std::string& face) const {
  FaceMesh fm;
  fm.nodes = mesh().face_nodes(face);
  std::unordered_map<std::size_t, int> local;
  fm.positions.resize(static_cast<Eigen::Index>(fm.nodes.size()), 3);
  for (std::size_t i = 0; i < fm.nodes.size(); ++i) {
    local[fm.nodes[i]] = static_cast<int>(i);
    fm.positions.row(static_cast<Eigen::Index>(i)) = mesh().node(fm.nodes[i]).transpose();
  }
  for (const auto& se : mesh().face(face)) {
    FaceMesh::Cell c{se.type, {}};
    for (int a = 0; a < node_count(se.type); ++a) c.nodes[a] = local.at(se.nodes[a]);
    fm.cells.push_back(c);
    const auto& v = c.nodes;
    switch (se.type) {
      case FaceType::Tri3:
        fm.triangles.push_back({v[0], v[1], v[2]});
        break;
      case FaceType::Quad4:
        fm.triangles.push_back({v[0], v[1], v[2]});
        fm.triangles.push_back({v[0], v[2], v[3]});
        break;
      case FaceType::Tri6:
        fm.triangles.push_back({v[0], v[3], v[5]});
        fm.triangles.push_back({v[3], v[1], v[4]});
        fm.triangles.push_back({v[5], v[4], v[2]});
        fm.triangles.push_back({v[3], v[4], v[5]});
        break;
      case FaceType::Quad8:
        fm.triangles.push_back({v[0], v[4], v[7]});
        fm.triangles.push_back({v[4], v[1], v[5]});
        fm.triangles.push_back({v[5], v[2], v[6]});
        fm.triangles.push_back({v[7], v[6], v[3]});
        fm.triangles.push_back({v[4], v[5], v[6]});
        fm.triangles.push_back({v[4], v[6], v[7]});
        break;
    }
    fm.triangle_cells.resize(fm.triangles.size(), static_cast<int>(fm.cells.size()) - 1);
  }
  fm.cell_elements = mesh().face_owners(face);
  return fm;
}

void StructuralSolver::set_face_tractions_at_quadrature_points(const std::string& face,
                                                               const MatrixX3& tractions) {
  const auto& op = face_operator(face);
  if (static_cast<std::size_t>(tractions.rows()) != op.num_qp) {
    throw Error("set_face_tractions_at_quadrature_points('" + face + "'): the face has " +
                std::to_string(op.num_qp) + " quadrature points, got " +
                std::to_string(tractions.rows()) +
                " tractions (one row per point, see face_quadrature_points())");
  }
  if (!tractions.allFinite())
    throw Error("set_face_tractions_at_quadrature_points('" + face + "'): non-finite traction");
  face_tractions_[face] = tractions;
  update_coupling_force();
}

void StructuralSolver::set_nodal_forces(const std::vector<std::size_t>& nodes,
                                        const MatrixX3& forces) {
  if (static_cast<std::size_t>(forces.rows()) != nodes.size()) {
    throw Error("set_nodal_forces: " + std::to_string(nodes.size()) + " nodes but " +
                std::to_string(forces.rows()) + " force rows");
  }
  for (auto n : nodes) {
    if (n >= mesh().num_nodes()) {
      throw Error("set_nodal_forces: node " + std::to_string(n) + " does not exist (the mesh has " +
                  std::to_string(mesh().num_nodes()) + " nodes)");
    }
  }
  if (!forces.allFinite()) throw Error("set_nodal_forces: non-finite force");
  nodal_force_nodes_ = nodes;
  nodal_forces_ = forces;
  update_coupling_force();
}

void StructuralSolver::clear_coupling_loads() {
  face_tractions_.clear();
  nodal_force_nodes_.clear();
  nodal_forces_.resize(0, 3);
  update_coupling_force();
}

double StructuralSolver::face_traction_work(const std::string& face, const MatrixX3& tractions,
                                            const Eigen::VectorXd& du) const {
  const auto& op = face_operator(face);
  if (static_cast<std::size_t>(tractions.rows()) != op.num_qp ||
      du.size() != coupling_force_.size())
    throw Error("face_traction_work('" + face + "'): " + std::to_string(op.num_qp) +
                " tractions and " + std::to_string(coupling_force_.size()) + " dofs expected");
  double w = 0.0;
  for (std::size_t k = 0; k < op.node.size(); ++k)
    w += op.coefficient[k] * tractions.row(static_cast<Eigen::Index>(op.qp[k]))
                                 .dot(du.segment<3>(3 * static_cast<Eigen::Index>(op.node[k])));
  return w;
}

void StructuralSolver::update_coupling_force() {
  coupling_force_.setZero();
  // f_a = sum_q N_a(x_q) t_q w_q over every face with tractions
  for (const auto& [face, t] : face_tractions_) {
    const auto& op = face_operator(face);
    for (std::size_t k = 0; k < op.node.size(); ++k) {
      coupling_force_.segment<3>(3 * static_cast<Eigen::Index>(op.node[k])) +=
          op.coefficient[k] * t.row(static_cast<Eigen::Index>(op.qp[k])).transpose();
    }
  }
  for (std::size_t k = 0; k < nodal_force_nodes_.size(); ++k) {
    coupling_force_.segment<3>(3 * static_cast<Eigen::Index>(nodal_force_nodes_[k])) +=
        nodal_forces_.row(static_cast<Eigen::Index>(k)).transpose();
  }
}

void StructuralSolver::evaluate_external_force(double t, Eigen::VectorXd& f) const {
  // F(t) = sum_l amplitude_l(t) F_l + F_coupling
  f = coupling_force_;
  for (std::size_t l = 0; l < load_vectors_.size(); ++l) {
    const double s = amplitude_at(model_.loads()[l].amplitude, t);
    if (s != 0.0) f += s * load_vectors_[l];
  }
}

void StructuralSolver::prescribed_values(double t, Eigen::VectorXd& uc) const {
  uc.resize(static_cast<Eigen::Index>(dofs_.constrained_dofs().size()));
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k) {
    const auto& g = constrained_value_[k];
    const auto dof = static_cast<std::size_t>(dofs_.constrained_dofs()[k]);
    uc[static_cast<Eigen::Index>(k)] = g ? g(mesh().node(dof / 3), t) : 0.0;
  }
}

// ---------------------------------------------------------------- analyses


void StructuralSolver::solve_static() {
  const auto t0 = Clock::now();
  last_was_static_ = true;
  if (uses_newton()) {
    static_.solve(*this, kin_, kin_.time);
    refresh_internal_force();
    update_failures();
    acceleration_valid_ = true;
    ++timings_.solves;
    timings_.solve += seconds_since(t0);
    return;
  }
  if (!static_factor_) {
    static_factor_ =
        std::make_unique<Factorisation>(options_.linear_solver, options_.fill_ordering);
    static_factor_->set_solve_threading(options_.solve_threading);
    static_factor_->set_factor_threading(options_.factor_threading);
    static_factor_->analyze(k_ff_);
    factorize_or_throw(*static_factor_, k_ff_, "static stiffness matrix K_ff");
    timings_.factor_nonzeros = static_factor_->factor_nonzeros();
    ++timings_.factorisations;
    timings_.factorisation += seconds_since(t0);
  }
  const auto t1 = Clock::now();
  evaluate_external_force(kin_.time, kin_.f);
  Eigen::VectorXd uc;
  prescribed_values(kin_.time, uc);
  // K_ff u_f = F_f - K_fc u_c
  Eigen::VectorXd rhs(static_cast<Eigen::Index>(dofs_.free_dofs().size()));
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    rhs[static_cast<Eigen::Index>(k)] = kin_.f[dofs_.free_dofs()[k]];
  if (uc.size() > 0 && uc.cwiseAbs().maxCoeff() > 0.0) rhs -= k_fc_ * uc;
  Eigen::VectorXd uf;
  static_factor_->solve(rhs, uf);
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    kin_.u[dofs_.free_dofs()[k]] = uf[static_cast<Eigen::Index>(k)];
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k)
    kin_.u[dofs_.constrained_dofs()[k]] = uc[static_cast<Eigen::Index>(k)];
  kin_.v.setZero();
  kin_.a.setZero();
  acceleration_valid_ = true;
  // the explicit path's reactions use f_int(u)
  if (options_.integrator == Integrator::CentralDifference) refresh_internal_force();
  ++timings_.solves;
  timings_.solve += seconds_since(t1);
}

void StructuralSolver::step_static(double dt) {
  if (!(dt > 0.0))
    throw Error("step_static: the time step must be positive, got " + std::to_string(dt));
  kin_.time += dt;
  ++steps_;
  solve_static();
}

void StructuralSolver::initialise_acceleration() {
  // M_ff a_f = F_f - (K u + C v)_f   (prescribed accelerations taken as zero)
  evaluate_external_force(kin_.time, kin_.f);
  Eigen::VectorXd r;
  if (!uses_newton()) {
    r = kin_.f - k_ * kin_.u;
  } else {
    refresh_internal_force();
    r = kin_.f - kin_.f_int;
  }
  add_damping_force(kin_.v, -1.0, r);
  Eigen::VectorXd rf(static_cast<Eigen::Index>(dofs_.free_dofs().size()));
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    rf[static_cast<Eigen::Index>(k)] = r[dofs_.free_dofs()[k]];
  Eigen::VectorXd af;
  if (options_.mass == MassType::Lumped) {
    af = rf.cwiseQuotient(Eigen::VectorXd(m_ff_.diagonal()));
  } else {
    // The consistent mass matrix is well conditioned (independent of the mesh size), so
    // Jacobi-preconditioned CG to round-off is far cheaper than a second factorisation.
    Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> cg;
    cg.setTolerance(1e-15);
    cg.setMaxIterations(1000);
    cg.compute(m_ff_);
    af = cg.solve(rf);
    if (cg.info() != Eigen::Success && !(cg.error() < 1e-12)) {
      throw Error("initial acceleration: CG on the mass matrix did not converge (error " +
                  std::to_string(cg.error()) + "); is the density > 0 everywhere?");
    }
  }
  kin_.a.setZero();
  for (std::size_t k = 0; k < dofs_.free_dofs().size(); ++k)
    kin_.a[dofs_.free_dofs()[k]] = af[static_cast<Eigen::Index>(k)];
  acceleration_valid_ = true;
}

void StructuralSolver::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw Error("step(dt): dt must be > 0, got " + std::to_string(dt));
  assemble_mass();
  last_was_static_ = false;
  const auto t0 = Clock::now();
  const double factorisation_before = timings_.factorisation;
  if (options_.integrator == Integrator::CentralDifference) {
    if (!acceleration_valid_) central_.initialise(*this, kin_);
    acceleration_valid_ = true;
    central_.step(*this, kin_, dt);
  } else {
    // Newmark: K_eff factorised once per step size while the operator's tangent is constant
    // (the linear path), Newton otherwise
    if (!acceleration_valid_) initialise_acceleration();
    newmark_.step(*this, kin_, dt);
    if (uses_newton()) refresh_internal_force();
  }
  update_failures();
  ++steps_;
  ++timings_.solves;
  // the step's factorisation (a new step size) is counted in timings_.factorisation
  timings_.solve += seconds_since(t0) - (timings_.factorisation - factorisation_before);
}

// ---------------------------------------------------------------- results

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

const std::vector<double>& StructuralSolver::element_frequencies_squared() const {
  if (!element_omega2_.empty() || mesh().num_elements() == 0) return element_omega2_;
  // Element eigenvalue bound (Irons 1970; Hughes, The Finite Element Method, 2000, section
  // 9.3): with a lumped mass, omega_max^2 of the mesh <= max_e lambda_max(M_e^-1 K_e), K_e and M_e
  // restricted to the element's free dofs (a constrained dof is zero in every mode). K_e is the
  // element stiffness at rest: the linear-elastic one (Hex8 as the path integrates it) or, for
  // a law, the elasticity tensor of its tangent at F = I.
  const ElementIntegrator full(Hex8Formulation::Full);
  std::vector<Matrix6> d_region;
  for (std::size_t r = 0; r < std::max<std::size_t>(1, mesh().region_names().size()); ++r) {
    const auto* law = model_.material_law(static_cast<int>(r));
    if (law == nullptr) {
      d_region.push_back(model_.material(static_cast<int>(r)).elasticity_matrix());
      continue;
    }
    std::vector<double> state(static_cast<std::size_t>(law->state_size()));
    std::vector<double> trial(state.size());
    law->initialise_state(state);
    MaterialResponse at_rest;
    law->evaluate(Mat3::Identity(), state, trial, at_rest);
    // Voigt D_ab = C_ijkl with a = (i, j), b = (k, l): xx yy zz xy yz zx
    static constexpr int kPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    Matrix6 d;
    for (int a = 0; a < 6; ++a) {
      for (int b = 0; b < 6; ++b) {
        d(a, b) = at_rest.tangent(3 * kPair[a][0] + kPair[a][1], 3 * kPair[b][0] + kPair[b][1]);
      }
    }
    d_region.push_back(d);
  }
  std::vector<char> is_free(ndof_, 0);
  for (auto dof : dofs_.free_dofs()) is_free[static_cast<std::size_t>(dof)] = 1;
  element_omega2_.assign(mesh().num_elements(), 0.0);
  ElementMatrix ke;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  std::vector<int> free_local;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    const ElementCoordinates x = element_coordinates(mesh(), e);
    const auto& d = d_region[static_cast<std::size_t>(e.region)];
    (nonlinear_ != nullptr ? full : integrator_).stiffness(e.type, x, d, ke);
    integrator_.lumped_mass(e.type, x, model_.density(e.region), m);
    free_local.clear();
    for (int a = 0; a < node_count(e.type); ++a) {
      for (int c = 0; c < 3; ++c) {
        if (is_free[3 * e.nodes[a] + static_cast<std::size_t>(c)]) free_local.push_back(3 * a + c);
      }
    }
    if (free_local.empty()) continue;
    // lambda_max of M^-1/2 K M^-1/2 on the free dofs
    const auto nf = static_cast<Eigen::Index>(free_local.size());
    Eigen::MatrixXd a(nf, nf);
    for (Eigen::Index i = 0; i < nf; ++i) {
      for (Eigen::Index j = 0; j < nf; ++j) {
        const int li = free_local[static_cast<std::size_t>(i)];
        const int lj = free_local[static_cast<std::size_t>(j)];
        a(i, j) = ke(li, lj) / std::sqrt(m[li / 3] * m[lj / 3]);
      }
    }
    element_omega2_[ei] = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly)
                              .eigenvalues()
                              .maxCoeff();
  }
  return element_omega2_;
}

void StructuralSolver::setup_mass_scaling() {
  const double target = options_.mass_scaling_time_step;
  if (!(target >= 0.0) || !std::isfinite(target))
    throw Error("mass scaling: the target time step must be a finite number >= 0 s (0: off), got " +
                std::to_string(target));
  if (target == 0.0) return;
  if (options_.integrator != Integrator::CentralDifference)
    throw Error(
        "mass scaling is for central-difference analyses (it raises the explicit stable step); "
        "Newmark and static analyses have no stable-step limit: remove the target time step");
  // s_e = (target / dt_e)^2 = target^2 omega_e^2 / 4 where dt_e = 2 / omega_e < target
  const auto& omega2 = element_frequencies_squared();
  mass_scale_.assign(mesh().num_elements(), 1.0);
  element_mass_.assign(mesh().num_elements(), 0.0);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    mass_scale_[ei] = std::max(1.0, 0.25 * target * target * omega2[ei]);
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), model_.density(e.region), m);
    element_mass_[ei] = m.head(node_count(e.type)).sum();
  }
  mass_ready_ = false;
  stable_step_ = -1.0;
}

std::size_t StructuralSolver::mass_scaled_elements() const {
  return static_cast<std::size_t>(
      std::count_if(mass_scale_.begin(), mass_scale_.end(), [](double s) { return s > 1.0; }));
}

double StructuralSolver::physical_mass() const {
  double total = 0.0;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    if (element_eroded(ei)) continue;
    if (!element_mass_.empty()) {
      total += element_mass_[ei];
      continue;
    }
    const Element& e = mesh().elements()[ei];
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), model_.density(e.region), m);
    total += m.head(node_count(e.type)).sum();
  }
  return total;
}

double StructuralSolver::added_mass() const {
  double added = 0.0;
  for (std::size_t ei = 0; ei < mass_scale_.size(); ++ei)
    if (!element_eroded(ei)) added += (mass_scale_[ei] - 1.0) * element_mass_[ei];
  return added;
}

double StructuralSolver::stable_time_step() const {
  if (stable_step_ > 0.0) return stable_step_;
  // dt_crit = 2 / omega_max, omega_max^2 <= max_e omega_e^2 / s_e (the scaled masses)
  const auto& omega2_e = element_frequencies_squared();
  double omega2 = 0.0;
  for (std::size_t ei = 0; ei < omega2_e.size(); ++ei)
    omega2 = std::max(omega2, omega2_e[ei] / mass_scale_factor(ei));
  Eigen::VectorXd nodal_mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh().num_nodes()));
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), element_density(ei), m);
    for (int a = 0; a < node_count(e.type); ++a) nodal_mass[static_cast<Eigen::Index>(e.nodes[a])] += m[a];
  }
  // contributions (a penalty contact): omega_max^2 <= the elements' + theirs (Weyl's inequality
  // for the sum of the two symmetric M^-1/2 K M^-1/2)
  if (nonlinear_ != nullptr)
    for (std::size_t c = 0; c < nonlinear_->num_contributions(); ++c)
      omega2 += nonlinear_->contribution(c).max_frequency_squared(nodal_mass);
  if (linear_sum_ != nullptr) omega2 += linear_sum_->max_frequency_squared(nodal_mass);
  stable_step_ = omega2 > 0.0 ? 2.0 / std::sqrt(omega2) : std::numeric_limits<double>::infinity();
  if (omega2 > 0.0 && options_.rayleigh_beta > 0.0) {
    // dt <= (2 / omega)(sqrt(1 + xi^2) - xi), xi = beta omega / 2: decreasing in omega, so the
    // bound on omega_max bounds the step
    const double xi = 0.5 * options_.rayleigh_beta * std::sqrt(omega2);
    stable_step_ *= std::sqrt(1.0 + xi * xi) - xi;
  }
  return stable_step_;
}

void StructuralSolver::add_damping_force(const Eigen::VectorXd& v, double sign,
                                         Eigen::VectorXd& r) const {
  // r += sign (alpha M + beta K0) v
  if (options_.rayleigh_alpha != 0.0) r += (sign * options_.rayleigh_alpha) * (m_ * v);
  if (options_.rayleigh_beta != 0.0)
    r += (sign * options_.rayleigh_beta) * ((nonlinear_ != nullptr ? k0_ : k_) * v);
}

void StructuralSolver::refresh_internal_force() {
  operator_->set_time(kin_.time, 0.0);  // the committed state (a rigid indenter where it is)
  operator_->evaluate(kin_.u, kin_.f_int, nullptr);
}

const SparseMatrix& StructuralSolver::mass() {
  assemble_mass();
  return m_;
}

void StructuralSolver::external_force(double t, Eigen::VectorXd& f) const {
  evaluate_external_force(t, f);
}

void StructuralSolver::apply_prescribed(double t, Eigen::VectorXd& u) const {
  Eigen::VectorXd& uc = prescribed_work_;  // sized once: no allocation per explicit step
  prescribed_values(t, uc);
  for (std::size_t k = 0; k < dofs_.constrained_dofs().size(); ++k)
    u[dofs_.constrained_dofs()[k]] = uc[static_cast<Eigen::Index>(k)];
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

// ---------------------------------------------------------------- state

SolverState StructuralSolver::save_state() const {
  SolverState s;
  s.time = kin_.time;
  s.steps = steps_;
  s.displacement = kin_.u;
  s.velocity = kin_.v;
  s.acceleration = kin_.a;
  s.external_force = kin_.f;
  s.acceleration_valid = acceleration_valid_;
  s.external_work = kin_.external_work;
  s.damping_work = kin_.damping_work;
  s.material_state = operator_->committed_state();
  s.coupling_force = coupling_force_;
  s.face_tractions = face_tractions_;
  s.nodal_force_nodes = nodal_force_nodes_;
  s.nodal_forces = nodal_forces_;
  s.factor_dt = newmark_.factor_dt();
  return s;
}

void StructuralSolver::restore_state(const SolverState& s) {
  const auto n = static_cast<Eigen::Index>(ndof_);
  if (s.displacement.size() != n || s.velocity.size() != n || s.acceleration.size() != n ||
      s.external_force.size() != n || s.coupling_force.size() != n) {
    throw Error("restore_state: the state has " + std::to_string(s.displacement.size()) +
                " dofs but this solver has " + std::to_string(ndof_) +
                " (state of another model?)");
  }
  kin_.time = s.time;
  steps_ = s.steps;
  kin_.u = s.displacement;
  kin_.v = s.velocity;
  kin_.a = s.acceleration;
  kin_.f = s.external_force;
  acceleration_valid_ = s.acceleration_valid;
  kin_.external_work = s.external_work;
  kin_.damping_work = s.damping_work;
  operator_->set_committed_state(s.material_state);
  coupling_force_ = s.coupling_force;
  face_tractions_ = s.face_tractions;
  nodal_force_nodes_ = s.nodal_force_nodes;
  nodal_forces_ = s.nodal_forces;
  // A state from another process (a restart file) carries the step size the factorisation was
  // made for; the same h gives the same K_eff and the same steps, bit for bit.
  if (s.factor_dt > 0.0 && s.factor_dt != newmark_.factor_dt()) {
    assemble_mass();  // K_eff needs M (assembled lazily at the first step)
    newmark_.factorise(*this, s.factor_dt);
  }
  if (nonlinear_ != nullptr && nonlinear_->material().erosion() && mass_ready_) {
    // the eroded elements of this state, not those of the last: the lumped mass again
    mass_ready_ = false;
    assemble_mass();
    central_.invalidate_mass();
  }
  if (uses_newton() || options_.integrator == Integrator::CentralDifference) {
    refresh_internal_force();
  }
}

}  // namespace partita::fem
