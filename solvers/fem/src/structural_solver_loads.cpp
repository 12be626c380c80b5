// StructuralSolver: faces (coupling geometry, face load operators), coupling loads, F(t) and the
// prescribed values g(t).
#include <unordered_map>

#include "partita/fem/error.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem {
namespace {

double amplitude_at(const TimeFunction& f, double t) {
  return f ? f(t) : 1.0;
}

}  // namespace

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

const FaceLoadOperator& StructuralSolver::face_operator(
    const std::string& face) const {
  auto it = face_operators_.find(face);
  if (it != face_operators_.end()) return it->second;
  FaceLoadOperator op;
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
  fm.cell_across = mesh().face_across(face);
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

}  // namespace partita::fem
