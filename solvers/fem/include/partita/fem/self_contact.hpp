#pragma once
#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "partita/fem/model.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem {

struct SelfContactOptions {
  // k = penalty_factor * k_node, k_node = sum_f E_f (A_f / n_f) / h_f over the node's faces in
  // contact (as IndenterContact); 0.1 is the scale explicit codes use by default for contact
  // between deformable parts (LS-DYNA's SLSFAC, LS-DYNA Theory Manual, "Contact-Impact
  // Algorithm": penalty method)
  double penalty_factor = 0.1;
  // the deepest penetration a node is caught at, as a fraction of the thickness h_f = V_e / A_f
  // of the element under the face it passes (0 < depth < 1): deeper lies the other side of a
  // plate, which is no contact
  double depth = 0.5;
};

// Node-to-face penalty contact of a body with itself (single-surface contact, as explicit codes
// name it), over the union of named faces; with erosion, over the faces it exposes (eroding
// single-surface contact). Two parts of one mesh that the bow or a tear brings together (a torn
// plate folding onto a web, the faces of a crushed element's neighbours closing the gap it
// leaves) then push each other apart instead of passing through each other.
//
// Faces: each face element split into triangles by its corners (a quadrilateral 0-1-2, 0-2-3);
// a face element takes part while its volume element is intact and, for a face between two
// elements (Mesh::add_interior_faces()), once the element across has eroded. Contact nodes:
// the nodes of those faces that an element still holds (set_detached()).
//
// For a node s and a triangle t of another element (s is not a node of the element t bounds),
// with x the current positions, n the triangle's unit outward normal and
//   g = n . (x_s - x_a)           (x_a a corner of t; g < 0: s lies behind the face),
// s is in contact with t where -depth h_t < g < 0 and s projects onto t, up to a margin of
// |g| / size_t outside its edges in barycentric terms (two triangles that meet at a convex
// kink, a warped quadrilateral's diagonal or the edge between two faces, leave a gap between
// their projections that grows as |g| times the kink's angle). A node in front of any face of
// an element (g >= 0) lies outside that element (a convex cell lies behind all its faces'
// planes): the element's other faces, behind whose planes it may lie beside a convex edge, do
// not touch it. Of the faces left, the one with the smallest |g| (the face the node has just
// passed), the first on a tie, so that each node has at most one contact. Then, with
// k = penalty_factor k_node(s),
//   p = -k g n on s,   -l_i p on the triangle's corners (l_i clamped to it),   W = 1/2 k g^2,
// a pair of equal and opposite forces (the momentum of the body is kept), the stored energy
// W in stored_energy(). The normal's turning with the face's nodes is left out of the forces
// (of relative size g / h): the energy of a contact closes to that order.
//
// Search: a Verlet list. At a refresh (set_time(t, 0): a run's start, an erosion, a restored
// state) and whenever a contact node has moved more than half the skin since the last build,
// the pairs (s, t) whose distance lies within depth h_t + skin are collected by a uniform grid
// of the triangles' boxes (skin = half the thinnest face element's h); between builds each step
// evaluates only those, so a step costs one pass over the contact nodes and one over the pairs.
// The result does not depend on when the list was built (each node's candidates are kept in
// triangle order), so a restart gives the same bits.
//
// Faces that join (erosion exposes them; every face at the start): a node they find already
// behind them, where the element between was crushed or distorted, would take the spring
// energy 1/2 k g^2 of that depth from nowhere. Such a contact keeps the depth it was found at
// as a pre-penetration and pushes only beyond it (p = k (|g| - pre) n, W = 1/2 k (|g| - pre)^2),
// the pre-penetration followed down as the node comes out (as the DEM's mesh contacts do with a
// face exposed under a particle). Likewise a contact with a triangle the node did not touch at
// the last committed configuration (a new contact, or one passed on from another triangle) can
// have grown only by the node's approach to that triangle since then: the spring takes up the
// overlap it had (with the other triangle, or none) plus that approach, and the rest of the depth
// is a pre-penetration. Else a node coming back within the caught depth from deeper, sliding
// under a face from beside it, or passed on to a deeper face would be pushed with 1/2 k g^2 of a
// depth no motion made. Committed state: per contact node the pre-penetration, the triangle it
// touched and its position; which faces took part.
//
// Explicit (central difference) analyses only: it offers no tangent. Stable step:
// max_frequency_squared() estimates M^-1 K_c's largest eigenvalue for a node in one pair whose
// triangle's corners are shared by a few pairs: 4 max_i k_i / m_i, k_i the stiffness the node
// has with every face around it exposed (its boundary faces and one side of each face between
// two elements), m_i its mass at the start.
class SelfContact final : public OperatorContribution {
 public:
  // Throws Error for an unknown face (listing the known ones), a face named twice, no face, a
  // bad option or a face element that bounds no volume element.
  SelfContact(std::string name, const Model& model, const std::vector<std::string>& faces,
              SelfContactOptions options = {});

  std::string_view name() const override { return name_; }
  void set_time(double t, double fraction) override;
  void add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
           const BlockAssembler& assembler) override;
  bool has_tangent() const override { return false; }
  double stored_energy() const override { return energy_; }
  double round_off() const override { return round_off_; }
  void commit() override;
  const std::vector<double>& committed_state() const override;
  void set_committed_state(const std::vector<double>& state) override;
  double max_frequency_squared(const Eigen::VectorXd& nodal_mass) const override;

  /// Nodes that have left the structure (every element around them eroded) take no part.
  void set_detached(std::function<bool(std::size_t node)> detached) { detached_ = std::move(detached); }
  /// Eroded volume elements: their faces leave, the faces between elements that they expose join.
  void set_eroded(std::function<bool(std::size_t element)> eroded) { eroded_ = std::move(eroded); }

  // Nodes in contact at the last add(), and the sum of |p| over them [N].
  std::size_t active_nodes() const { return active_; }
  double total_normal_force() const { return force_sum_; }
  // Triangles taking part and candidate pairs of the current list (diagnostics).
  std::size_t triangles_in_contact_surface() const;
  std::size_t candidate_pairs() const { return candidates_.size(); }
  std::size_t surface_nodes() const { return nodes_.size(); }
  std::size_t list_builds() const { return builds_; }

 private:
  struct Triangle {
    std::array<std::size_t, 3> nodes;
    std::size_t face;    // index into the face elements
    double depth;        // depth * h_f [m]
  };
  std::string name_;
  const Mesh& mesh_;
  SelfContactOptions options_;
  // face elements (deduplicated over the named faces): owner, element across (num_elements():
  // none), the spring factor E A_f / (n_f h_f)
  std::vector<SurfaceElement> faces_;
  std::vector<std::size_t> face_owner_, face_across_;
  std::vector<double> face_stiffness_;
  std::vector<Triangle> triangles_;
  std::vector<char> face_active_;
  std::vector<std::size_t> nodes_;       // every node of the faces
  std::vector<std::size_t> node_slot_;   // mesh node -> index in nodes_
  std::vector<double> k_node_;           // per contact node, times penalty_factor (0: inactive)
  std::vector<double> k_bound_;          // per contact node: the largest k_node_ erosion can give
  double skin_ = 0.0;
  // the Verlet list: for node j, candidates_[start_[j] .. start_[j+1]) (triangle indices)
  std::vector<std::size_t> start_, candidates_;
  std::vector<Vec3> x_built_;            // contact nodes' positions at the last build
  bool refresh_ = true;
  std::size_t builds_ = 0;
  // scratch of the build (kept: no allocation between builds)
  std::vector<std::size_t> cell_start_, cell_items_, cell_fill_;
  std::vector<std::array<double, 6>> boxes_;
  struct Probe {  // a node against one candidate triangle (add()'s scratch)
    Vec3 normal;
    double gap, outside, size;
    std::array<double, 3> weights;
    bool valid, owner_outside;
  };
  std::vector<Probe> probe_;
  // per contact node the pre-penetration (committed, of the last add()); per face element
  // whether it took part at the last committed configuration (a face not there then is new)
  std::vector<double> pre_, pre_trial_;
  std::vector<char> face_active_committed_;
  // per contact node, at the last committed configuration and at the last add(): the triangle
  // it touched (behind which it lay, pushing or not; none: triangles_.size()), its position
  std::vector<std::size_t> held_, held_trial_;
  std::vector<Vec3> x_committed_, x_trial_;
  mutable std::vector<double> state_;
  double energy_ = 0.0, round_off_ = 0.0, force_sum_ = 0.0;
  std::size_t active_ = 0;
  std::function<bool(std::size_t)> detached_, eroded_;

  void update_active();
  void build_list(const Eigen::VectorXd& u);
  Vec3 position(const Eigen::VectorXd& u, std::size_t node) const {
    return mesh_.node(node) + u.segment<3>(3 * static_cast<Eigen::Index>(node));
  }
};

}  // namespace partita::fem
