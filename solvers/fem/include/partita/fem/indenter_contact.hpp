#pragma once
#include <functional>
#include <limits>
#include <cstddef>
#include <string>
#include <vector>

#include "partita/fem/model.hpp"
#include "partita/fem/operator_contribution.hpp"
#include "partita/fem/rigid_indenter.hpp"

namespace partita::fem {

struct IndenterContactOptions {
  // k_n = penalty_factor * E * A_node / h (see IndenterContact)
  double penalty_factor = 1.0;
  double friction = 0.0;            // Coulomb coefficient mu (0: frictionless)
  double tangential_factor = 1.0;   // k_t = tangential_factor * k_n (elastic slip of the stick)
  // How the body's work is booked over a step in which a node touches or leaves: false (default)
  // the trapezoid 1/2 (p_0 + p_1) . dd, the work the central difference's own energy follows
  // (Verlet: its kinetic energy is the forces' trapezoidal work plus dt^2/8 sum |F|^2/m, which
  // does not accumulate); true: only over the part of the step with g < 0 (the gap linear over
  // the step), exact for the springs (a touch from rest books 1/2 k g^2), which leaves in the
  // books the energy the central difference gives a node it releases while moving (about
  // 1/2 (1 - s) p . du): a chattering contact then shows a few per cent for a while.
  bool path_work = false;
};

// Node-to-rigid-surface penalty contact of a RigidIndenter with the nodes of one or more named
// faces (their union: a node on two of them is one contact node, with the stiffness of the face
// elements around it on both): one contribution to the FE operator (OperatorContribution),
// beside the material's.
//
// Normal: for a face node at x = X + u and the indenter displaced by d, g = g_shape(x - d) (the
// shape's signed distance, < 0 inside) and n its outward normal; where g < 0
//   p = -k_n g n  (on the node),   f_int += -p,   W = 1/2 k_n g^2,
// and the body gets -p. Penalty stiffness per node, from the elements under the face:
//   k_n = penalty_factor * sum_f E_f (A_f / n_f) / h_f,   h_f = V_e / A_f,
// A_f the area of face element f (its corners' polygon), n_f its node count, V_e the volume of
// the volume element it bounds and E_f that element's Young's modulus (Model::material). This is
// the usual choice of explicit codes, a spring as stiff as the element under the node (LS-DYNA's
// penalty contact, k = f K A^2 / V with the bulk modulus K; Wriggers, Computational Contact
// Mechanics, 2nd ed. 2006, section 10.3, on choosing penalty parameters from the element
// stiffness); penalty_factor 1 lets the node penetrate about as much as the element under it
// deforms, 10-100 makes the penetration that much smaller at the cost of a smaller stable step.
//
// Friction (friction > 0): Coulomb with an elastic-slip regularisation, k_t = tangential_factor
// k_n. Per node the committed tangential force f_t (on the node) and displacement u are history:
//   du_t = (I - n n^T)((u - u_c) - (d - d_c)),  f_t,trial = P(f_t,c) - k_t du_t,
//   |f_t,trial| <= mu |p|: stick, f_t = f_t,trial; else slip, f_t = mu |p| f_t,trial/|f_t,trial|,
//   dissipated += mu |p| (|f_t,trial| - mu |p|) / k_t,
// P(f_t,c) the committed force turned into the current tangent plane (its length kept); a node
// that separates forgets its f_t. Stored energy adds |f_t|^2 / (2 k_t).
//
// The body's work on the structure (RigidIndenter::work()), node by node over a step: the
// integral of the node's contact force along the body's path, the gap taken as linear in time
// between its values at the step's ends (g_0, g_1), as it is for a plane and straight paths:
//   in contact at both ends:  1/2 (p_0 + p_1) . dd         (the trapezoid: exact for k_n g)
//   touching during the step (g_0 >= 0 > g_1):  1/2 (-g_1 / (g_0 - g_1)) p_1 . dd
//   leaving during the step (g_0 < 0 <= g_1):   1/2 ( g_0 / (g_0 - g_1)) p_0 . dd
// (the force is zero over the part of the step before the touch, after the release). The
// trapezoid over a whole step in which a node first touches booked 1/2 k_n |g_1| |dd|, up to
// (|g_1| + g_0) / |g_1| times the spring energy 1/2 k_n g_1^2 that the penalty springs hold then.
// What the central difference gives the nodes at a touch or a release differs from the exact
// work of the force on their own path (the force acts from a step's end on); that is the
// integrator's, not the books': a node at rest when it is touched gains nothing over the step,
// and the bow's work is then exactly the springs' energy.
//
// Tangent (static and Newmark, driven indenters): k_n n n^T per node in contact, plus k_t
// (I - n n^T) in stick and mu |p| k_t / |f_t,trial| (I - n n^T - t t^T) in slip (the friction
// force's dependence on the normal force and the normal's turning, and the curvature term
// k_n g dn/dx, of relative size g/R, are left out: Newton still converges, more slowly where
// they matter). A free indenter offers no tangent (its motion is explicit): central difference
// only.
//
// Stable step: max_frequency_squared() bounds M^-1 K_c's largest eigenvalue by Gershgorin on the
// mass-scaled contact stiffness: max(k_n, k_t) (1/m_i + 1/sqrt(m_i m_b)) for node i, and
// sum_i max(k_n, k_t)(1/m_b + 1/sqrt(m_i m_b)) for a free body of mass m_b (over all face nodes);
// the solver adds it to the elements' omega^2 (Weyl: lambda_max(A + B) <= lambda_max(A) +
// lambda_max(B)).
class IndenterContact final : public OperatorContribution {
 public:
  // Throws Error for an unknown face (listing the known ones), a bad option or a face element
  // that bounds no volume element.
  IndenterContact(std::string name, const Model& model, const std::string& face,
                  RigidIndenter indenter, IndenterContactOptions options = {});
  // The union of several faces (at least one; each named once).
  IndenterContact(std::string name, const Model& model, const std::vector<std::string>& faces,
                  RigidIndenter indenter, IndenterContactOptions options = {});

  std::string_view name() const override { return name_; }
  void set_time(double t, double fraction) override;
  void add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
           const BlockAssembler& assembler) override;
  bool has_tangent() const override { return !indenter_.is_free(); }
  void commit() override;
  double stored_energy() const override { return energy_; }
  double dissipated_work() const override { return friction_work_; }
  // eps |(k_n (|X| + |u| + |d| + |c|) + |p| + |f_t|)| over the nodes in contact: a gap is a
  // difference of coordinates, rounded to eps of their size, times k_n
  double round_off() const override { return round_off_; }
  double max_frequency_squared(const Eigen::VectorXd& nodal_mass) const override;
  const std::vector<double>& committed_state() const override;
  void set_committed_state(const std::vector<double>& state) override;

  /// Nodes that have left the surface (every element around them eroded: the solver's
  /// node_detached()) take no contact force; default: none.
  void set_detached(std::function<bool(std::size_t node)> detached) {
    detached_ = std::move(detached);
  }
  /// Eroded volume elements (the solver's element_eroded()): at each evaluation at the committed
  /// configuration (a refresh after an erosion, a restored state) k_n is summed again over the
  /// face elements whose volume element is intact, so that a node on the edge of a hole keeps
  /// the stiffness of the elements it still has, in proportion to its mass (its k_n / m_i, and
  /// with it the stable step, stays that of the intact surface); default: none. A face between
  /// two elements (Mesh::add_interior_faces()) counts once the element across has eroded: the
  /// indenter meets the faces that erosion exposes (a web under a torn plate).
  void set_eroded(std::function<bool(std::size_t element)> eroded) { eroded_ = std::move(eroded); }

  const RigidIndenter& indenter() const { return indenter_; }
  // The face node deepest inside the indenter with the structure undeformed (its reference
  // coordinates) and the indenter at its committed position: depth = -g of that node, > 0 where
  // it lies inside the body, <= 0 (minus the smallest gap) where none does. A set-up check: a
  // body that starts inside the structure (a length in the wrong unit, a position off by a
  // face) puts penalty forces of k_n times the overlap on the nodes at the first evaluation.
  struct DeepestNode {
    std::size_t node = 0;  // mesh node index (meaningless when the faces have no node)
    double depth = -std::numeric_limits<double>::infinity();
  };
  DeepestNode deepest_node() const;
  // A force on the body from outside this model (RigidIndenter::set_external_force).
  void set_external_force(const Vec3& force) { indenter_.set_external_force(force); }
  // Force of the last add() on the indenter [N] (after commit(): the committed one).
  const Vec3& contact_force() const { return force_on_body_; }
  std::size_t active_nodes() const { return active_; }
  const std::vector<std::size_t>& nodes() const { return nodes_; }
  // The contact force on each of nodes() [N] at the committed configuration (zero apart).
  const std::vector<Vec3>& node_forces() const { return force_committed_; }
  const std::vector<double>& penalty_stiffness() const { return k_normal_; }

 private:
  std::string name_;
  const Mesh& mesh_;
  RigidIndenter indenter_;
  IndenterContactOptions options_;
  std::vector<std::size_t> nodes_;   // the face's nodes
  std::vector<double> k_normal_;     // per face node [N/m]
  // friction history per face node (friction > 0): committed and trial tangential force, the
  // committed displacement and that of the last add()
  std::vector<Vec3> ft_committed_, ft_trial_, u_committed_, u_trial_;
  // per face node, the gap and the contact force on the node (zero apart) at the committed
  // configuration and at the last add() (the body's work over a step)
  std::vector<double> gap_committed_, gap_trial_;
  std::vector<Vec3> force_committed_, force_trial_;
  double work_trial_ = 0.0;  // the body's work over the step to the last add()'s configuration
  double friction_work_ = 0.0, friction_work_trial_ = 0.0;
  double energy_ = 0.0, round_off_ = 0.0;
  Vec3 force_on_body_ = Vec3::Zero();
  std::size_t active_ = 0;
  mutable std::vector<double> state_;
  double step_start_ = 0.0;  // committed time at the last set_time(t, 0)
  std::function<bool(std::size_t)> detached_, eroded_;
  // per face element (the faces' elements one face after the other): the element, the volume
  // element it bounds and its factor E A_f / (n_f h_f)
  std::vector<SurfaceElement> face_elements_;
  std::vector<std::size_t> face_owner_;
  std::vector<std::size_t> face_across_;  // the element across a face (num_elements(): none)
  std::vector<double> face_stiffness_;
  std::vector<std::size_t> node_slot_;  // mesh node -> its index in nodes_ (face nodes only)
  void sum_penalty_stiffness();  // k_normal_ from the face elements (the intact ones)
};

}  // namespace partita::fem
