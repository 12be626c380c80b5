#include "partita/fem/indenter_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_area.hpp"
#include "partita/fem/quadrature.hpp"

namespace partita::fem {

IndenterContact::IndenterContact(std::string name, const Model& model, const std::string& face,
                                 RigidIndenter indenter, IndenterContactOptions options)
    : IndenterContact(std::move(name), model, std::vector<std::string>{face}, std::move(indenter),
                      options) {}

IndenterContact::IndenterContact(std::string name, const Model& model,
                                 const std::vector<std::string>& faces, RigidIndenter indenter,
                                 IndenterContactOptions options)
    : name_(std::move(name)), mesh_(model.mesh()), indenter_(std::move(indenter)), options_(options) {
  if (!(options_.penalty_factor > 0.0) || !std::isfinite(options_.penalty_factor))
    throw Error("contact '" + name_ + "': the penalty factor must be > 0");
  if (!(options_.friction >= 0.0) || !std::isfinite(options_.friction))
    throw Error("contact '" + name_ + "': the friction coefficient must be >= 0");
  if (!(options_.tangential_factor > 0.0))
    throw Error("contact '" + name_ + "': the tangential penalty factor must be > 0");
  if (faces.empty()) throw Error("contact '" + name_ + "': no face given");
  node_slot_.assign(mesh_.num_nodes(), 0);
  std::vector<char> taken(mesh_.num_nodes(), 0);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::string& face = faces[i];
    if (std::find(faces.begin(), faces.begin() + static_cast<std::ptrdiff_t>(i), face) !=
        faces.begin() + static_cast<std::ptrdiff_t>(i))
      throw Error("contact '" + name_ + "': the face '" + face + "' is named twice");
    const auto& elements = mesh_.face(face);  // throws, listing the faces, if unknown
    std::vector<std::size_t> owners;           // the volume element each face element bounds
    std::vector<std::size_t> across;           // and the one across (a face between elements)
    try {
      owners = mesh_.face_owners(face);
      across = mesh_.face_across(face);
    } catch (const Error& e) {
      throw Error("contact '" + name_ + "': " + e.what());
    }
    for (const std::size_t n : mesh_.face_nodes(face))  // the union, in the faces' order
      if (!taken[n]) {
        taken[n] = 1;
        nodes_.push_back(n);
      }
    for (std::size_t f = 0; f < elements.size(); ++f) {
      const auto& s = elements[f];
      const Element& el = mesh_.element(owners[f]);
      const double area = corner_area(mesh_, s);
      const double h = element_volume(mesh_, el) / area;
      // k_n += factor E (A_f / n_f) / h_f
      const double modulus = model.material(el.region).youngs_modulus;
      const auto nf = static_cast<double>(node_count(s.type));
      face_stiffness_.push_back(options_.penalty_factor * modulus * (area / nf) / h);
      face_elements_.push_back(s);
      face_owner_.push_back(owners[f]);
      face_across_.push_back(across[f]);
    }
  }
  for (std::size_t j = 0; j < nodes_.size(); ++j) node_slot_[nodes_[j]] = j;
  sum_penalty_stiffness();
  gap_committed_.assign(nodes_.size(), 1.0);  // apart: the first add() at rest sets them
  gap_trial_ = gap_committed_;
  force_committed_.assign(nodes_.size(), Vec3::Zero());
  force_trial_ = force_committed_;
  if (options_.friction > 0.0) {
    ft_committed_.assign(nodes_.size(), Vec3::Zero());
    ft_trial_ = ft_committed_;
    u_committed_ = ft_committed_;
    u_trial_ = ft_committed_;
  }
}

void IndenterContact::sum_penalty_stiffness() {
  // in the face elements' order, as the first sum: the same bits while nothing is eroded
  k_normal_.assign(nodes_.size(), 0.0);
  const std::size_t none = mesh_.num_elements();
  for (std::size_t f = 0; f < face_elements_.size(); ++f) {
    if (eroded_ && eroded_(face_owner_[f])) continue;
    // a face between two elements touches only once erosion has taken the element across
    if (face_across_[f] != none && !(eroded_ && eroded_(face_across_[f]))) continue;
    for (auto n : face_elements_[f].node_span()) k_normal_[node_slot_[n]] += face_stiffness_[f];
  }
}

void IndenterContact::set_time(double t, double fraction) {
  if (fraction == 0.0) step_start_ = indenter_.time();
  indenter_.move_to(fraction == 1.0   ? t
                    : fraction == 0.0 ? indenter_.time()
                                      : step_start_ + fraction * (t - step_start_));
}

void IndenterContact::add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
                          const BlockAssembler& assembler) {
  const Vec3 d = indenter_.trial_displacement();
  const Vec3 dd = d - indenter_.displacement();
  const bool at_committed = indenter_.trial_time() == indenter_.time() && d == indenter_.displacement();
  if (at_committed && eroded_) sum_penalty_stiffness();
  const RigidShape& shape = indenter_.shape();
  const bool friction = options_.friction > 0.0;
  energy_ = 0.0;
  friction_work_trial_ = 0.0;
  active_ = 0;
  double round_off2 = 0.0;
  Vec3 on_body = Vec3::Zero();
  double work = 0.0;
  ElementMatrix ke(3, 3);
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    const std::size_t node = nodes_[j];
    const auto at = 3 * static_cast<Eigen::Index>(node);
    const Vec3 ui = u.segment<3>(at);
    if (friction) u_trial_[j] = ui;
    const ShapeDistance s = shape.distance(mesh_.node(node) + ui - d);
    gap_trial_[j] = s.gap;
    const Vec3& force_before = force_committed_[j];
    const bool touched_before = force_before.squaredNorm() > 0.0;
    // apart, eroded away, or without a face left to touch (every face around the node eroded
    // while an element still holds it: no penalty stiffness)
    if (!(s.gap < 0.0) || (detached_ && detached_(node)) || !(k_normal_[j] > 0.0)) {
      if (friction) ft_trial_[j].setZero();
      force_trial_[j].setZero();
      // released during the step: the force acted over the part g < 0, down from p_0
      if (touched_before) {
        const double g0 = gap_committed_[j];
        const double inside = options_.path_work && s.gap > 0.0 && g0 < 0.0 ? g0 / (g0 - s.gap) : 1.0;
        work += 0.5 * inside * force_before.dot(dd);
      }
      continue;
    }
    ++active_;
    const double kn = k_normal_[j];
    const Vec3& n = s.normal;
    // p = -k_n g n on the node;  f_int += -p;  W = 1/2 k_n g^2
    const Vec3 p = -kn * s.gap * n;
    Vec3 force = p;
    energy_ += 0.5 * kn * s.gap * s.gap;
    if (k != nullptr) ke = kn * n * n.transpose();
    if (friction) {
      const double kt = options_.tangential_factor * kn;
      const Mat3 tangent_projector = Mat3::Identity() - n * n.transpose();
      // du_t = (I - n n^T)((u - u_c) - (d - d_c));  f_t,trial = P(f_t,c) - k_t du_t
      const Vec3 du_t = tangent_projector * ((ui - u_committed_[j]) - dd);
      Vec3 ft_old = tangent_projector * ft_committed_[j];
      if (ft_old.norm() > 0.0) ft_old *= ft_committed_[j].norm() / ft_old.norm();
      Vec3 ft = ft_old - kt * du_t;
      const double limit = options_.friction * p.norm(), trial = ft.norm();
      if (trial > limit) {
        // return to the cone: f_t = mu |p| t, t = f_t,trial / |f_t,trial|
        const Vec3 t = ft / trial;
        ft = limit * t;
        friction_work_trial_ += limit * (trial - limit) / kt;
        if (k != nullptr) ke += kt * limit / trial * (tangent_projector - t * t.transpose());
      } else if (k != nullptr) {
        ke += kt * tangent_projector;
      }
      ft_trial_[j] = ft;
      energy_ += 0.5 * ft.squaredNorm() / kt;
      force += ft;
    }
    f.segment<3>(at) -= force;
    on_body -= force;
    force_trial_[j] = force;
    if (touched_before) {
      work += 0.5 * (force_before + force).dot(dd);  // in contact at both ends: the trapezoid
    } else {
      // touched during the step: the force acted over the part g < 0, up to p_1
      const double g0 = gap_committed_[j];
      const double inside = options_.path_work && g0 > 0.0 ? s.gap / (s.gap - g0) : 1.0;
      work += 0.5 * inside * force.dot(dd);
    }
    const double scale = kn * (mesh_.node(node).norm() + ui.norm() + d.norm() + std::abs(s.gap)) +
                         force.norm();
    round_off2 += scale * scale;
    if (k != nullptr) assembler.add(*k, std::span<const std::size_t>(&node, 1), ke);
  }
  force_on_body_ = on_body;
  round_off_ = std::numeric_limits<double>::epsilon() * std::sqrt(round_off2);
  indenter_.set_contact_force(on_body);
  work_trial_ = work;
  if (at_committed) {
    // at the committed configuration (a run's start, a restored state, a refresh after an
    // erosion): its gaps and forces are the step's start
    gap_committed_ = gap_trial_;
    force_committed_ = force_trial_;
    work_trial_ = 0.0;
  }
}

IndenterContact::DeepestNode IndenterContact::deepest_node() const {
  DeepestNode deepest;
  const Vec3& d = indenter_.displacement();
  for (const std::size_t node : nodes_) {
    const double depth = -indenter_.shape().distance(mesh_.node(node) - d).gap;
    if (depth > deepest.depth) deepest = {node, depth};
  }
  return deepest;
}

void IndenterContact::commit() {
  indenter_.commit(work_trial_);
  work_trial_ = 0.0;
  gap_committed_ = gap_trial_;
  force_committed_ = force_trial_;
  if (options_.friction > 0.0) {
    ft_committed_ = ft_trial_;
    u_committed_ = u_trial_;
    friction_work_ += friction_work_trial_;
    friction_work_trial_ = 0.0;
  }
}

double IndenterContact::max_frequency_squared(const Eigen::VectorXd& nodal_mass) const {
  const double kfactor = std::max(1.0, options_.friction > 0.0 ? options_.tangential_factor : 0.0);
  const double mb = indenter_.is_free() ? indenter_.mass() : 0.0;
  double node_max = 0.0, body = 0.0;
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    const double m = nodal_mass[static_cast<Eigen::Index>(nodes_[j])];
    if (!(m > 0.0)) continue;
    const double kmax = kfactor * k_normal_[j];
    // Gershgorin rows of M^-1/2 K_c M^-1/2: node k/m_i + k/sqrt(m_i m_b); body sum of the same
    // with 1/m_b
    const double cross = mb > 0.0 ? kmax / std::sqrt(m * mb) : 0.0;
    node_max = std::max(node_max, kmax / m + cross);
    if (mb > 0.0) body += kmax / mb + cross;
  }
  return std::max(node_max, body);
}

const std::vector<double>& IndenterContact::committed_state() const {
  state_.assign(RigidIndenter::kStateSize, 0.0);
  indenter_.write_state(state_);
  if (options_.friction > 0.0) {
    state_.push_back(friction_work_);
    for (std::size_t j = 0; j < nodes_.size(); ++j)
      for (const Vec3* v : {&ft_committed_[j], &u_committed_[j]})
        state_.insert(state_.end(), v->data(), v->data() + 3);
  }
  return state_;
}

void IndenterContact::set_committed_state(const std::vector<double>& state) {
  const std::size_t expected =
      RigidIndenter::kStateSize + (options_.friction > 0.0 ? 1 + 6 * nodes_.size() : 0);
  if (state.size() != expected)
    throw Error("contact '" + name_ + "': a state of " + std::to_string(state.size()) +
                " values was given, it keeps " + std::to_string(expected));
  indenter_.read_state(std::span<const double>(state.data(), RigidIndenter::kStateSize));
  if (options_.friction > 0.0) {
    const double* p = state.data() + RigidIndenter::kStateSize;
    friction_work_ = *p++;
    for (std::size_t j = 0; j < nodes_.size(); ++j) {
      for (Vec3* v : {&ft_committed_[j], &u_committed_[j]})
        for (int c = 0; c < 3; ++c) (*v)[c] = *p++;
    }
    ft_trial_ = ft_committed_;
    u_trial_ = u_committed_;
  }
  force_on_body_ = indenter_.contact_force();
}

}  // namespace partita::fem
