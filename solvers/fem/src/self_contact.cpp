#include "partita/fem/self_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_area.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/geometry/closest_point.hpp"

namespace partita::fem {
namespace {

bool has_node(const Element& e, std::size_t node) {
  const auto span = e.node_span();
  return std::find(span.begin(), span.end(), node) != span.end();
}

}  // namespace

SelfContact::SelfContact(std::string name, const Model& model, const std::vector<std::string>& faces,
                         SelfContactOptions options)
    : name_(std::move(name)), mesh_(model.mesh()), options_(options) {
  if (!(options_.penalty_factor > 0.0) || !std::isfinite(options_.penalty_factor))
    throw Error("self contact '" + name_ + "': the penalty factor must be > 0, got " +
                std::to_string(options_.penalty_factor));
  if (!(options_.depth > 0.0 && options_.depth < 1.0))
    throw Error("self contact '" + name_ + "': depth is a fraction of the element's thickness, "
                "0 < depth < 1, got " + std::to_string(options_.depth));
  if (faces.empty()) throw Error("self contact '" + name_ + "': no face given");
  // face elements over the named faces, each once (a face element listed under two names: the
  // same owner and corners)
  std::map<std::pair<std::size_t, std::array<std::size_t, 4>>, std::size_t> seen;
  std::vector<char> taken(mesh_.num_nodes(), 0);
  k_bound_.assign(mesh_.num_nodes(), 0.0);
  double thinnest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const std::string& face = faces[i];
    if (std::find(faces.begin(), faces.begin() + static_cast<std::ptrdiff_t>(i), face) !=
        faces.begin() + static_cast<std::ptrdiff_t>(i))
      throw Error("self contact '" + name_ + "': the face '" + face + "' is named twice");
    const auto& elements = mesh_.face(face);  // throws, listing the faces, if unknown
    std::vector<std::size_t> owners, across;
    try {
      owners = mesh_.face_owners(face);
      across = mesh_.face_across(face);
    } catch (const Error& e) {
      throw Error("self contact '" + name_ + "': " + e.what());
    }
    for (std::size_t f = 0; f < elements.size(); ++f) {
      const SurfaceElement& s = elements[f];
      const int corners = corner_count(s.type);
      std::array<std::size_t, 4> key{};
      key.fill(mesh_.num_nodes());
      for (int c = 0; c < corners; ++c) key[static_cast<std::size_t>(c)] = s.nodes[static_cast<std::size_t>(c)];
      std::sort(key.begin(), key.end());
      if (!seen.emplace(std::make_pair(owners[f], key), faces_.size()).second) continue;
      const Element& el = mesh_.element(owners[f]);
      const double area = corner_area(mesh_, s);
      const double h = element_volume(mesh_, el) / area;
      if (!(area > 0.0) || !(h > 0.0))
        throw Error("self contact '" + name_ + "': a face element of '" + face +
                    "' has no area or bounds an element of no volume (element " +
                    std::to_string(owners[f]) + ")");
      thinnest = std::min(thinnest, h);
      const double modulus = model.material(el.region).youngs_modulus;
      const auto nf = static_cast<double>(node_count(s.type));
      const std::size_t index = faces_.size();
      faces_.push_back(s);
      face_owner_.push_back(owners[f]);
      face_across_.push_back(across[f]);
      face_stiffness_.push_back(options_.penalty_factor * modulus * (area / nf) / h);
      // the triangles' winding such that (b - a) x (c - a) points out of the element (away
      // from its centroid), whatever order the face's nodes come in
      auto n = s.nodes;
      Vec3 centre = Vec3::Zero(), face_centre = Vec3::Zero();
      for (const std::size_t node : el.node_span()) centre += mesh_.node(node);
      centre /= static_cast<double>(el.node_span().size());
      for (int c = 0; c < corners; ++c) face_centre += mesh_.node(n[static_cast<std::size_t>(c)]);
      face_centre /= corners;
      const Vec3 normal = (mesh_.node(n[1]) - mesh_.node(n[0])).cross(mesh_.node(n[2]) - mesh_.node(n[0]));
      if (normal.dot(face_centre - centre) < 0.0) std::swap(n[1], n[corners - 1]);
      triangles_.push_back({{n[0], n[1], n[2]}, index, options_.depth * h});
      if (corners == 4) triangles_.push_back({{n[0], n[2], n[3]}, index, options_.depth * h});
      for (const std::size_t node : s.node_span()) {
        // the most a node's stiffness can become: its boundary faces, and of a face between two
        // elements one side (erosion exposes it from the side whose element stays)
        k_bound_[node] += (across[f] == mesh_.num_elements() ? 1.0 : 0.5) * face_stiffness_.back();
      }
      for (const std::size_t node : s.node_span())
        if (!taken[node]) {
          taken[node] = 1;
          nodes_.push_back(node);
        }
    }
  }
  if (faces_.empty()) throw Error("self contact '" + name_ + "': the faces hold no face element");
  std::sort(nodes_.begin(), nodes_.end());
  node_slot_.assign(mesh_.num_nodes(), 0);
  for (std::size_t j = 0; j < nodes_.size(); ++j) node_slot_[nodes_[j]] = j;
  for (std::size_t j = 0; j < nodes_.size(); ++j) k_bound_[j] = k_bound_[nodes_[j]];  // by slot (nodes_ sorted: j <= nodes_[j])
  k_bound_.resize(nodes_.size());
  skin_ = 0.5 * thinnest;
  face_active_.assign(faces_.size(), 0);
  k_node_.assign(nodes_.size(), 0.0);
  x_built_.assign(nodes_.size(), Vec3::Zero());
  start_.assign(nodes_.size() + 1, 0);
  boxes_.resize(triangles_.size());
  pre_.assign(nodes_.size(), 0.0);
  pre_trial_ = pre_;
  face_active_committed_.assign(faces_.size(), 0);  // at the start every face is new
  held_.assign(nodes_.size(), triangles_.size());
  held_trial_ = held_;
  x_committed_.assign(nodes_.size(), Vec3::Zero());
  x_trial_ = x_committed_;
  update_active();
}

std::size_t SelfContact::triangles_in_contact_surface() const {
  std::size_t n = 0;
  for (const auto& t : triangles_) n += face_active_[t.face] ? 1 : 0;
  return n;
}

void SelfContact::update_active() {
  const std::size_t none = mesh_.num_elements();
  std::fill(k_node_.begin(), k_node_.end(), 0.0);
  for (std::size_t f = 0; f < faces_.size(); ++f) {
    const bool owner_in = !(eroded_ && eroded_(face_owner_[f]));
    const bool exposed = face_across_[f] == none || (eroded_ && eroded_(face_across_[f]));
    face_active_[f] = owner_in && exposed ? 1 : 0;
    if (!face_active_[f]) continue;
    for (const std::size_t node : faces_[f].node_span()) k_node_[node_slot_[node]] += face_stiffness_[f];
  }
  if (detached_)
    for (std::size_t j = 0; j < nodes_.size(); ++j)
      if (detached_(nodes_[j])) k_node_[j] = 0.0;
}

void SelfContact::set_time(double /*t*/, double fraction) {
  if (fraction == 0.0) refresh_ = true;  // a start, an erosion, a restored state
}

void SelfContact::build_list(const Eigen::VectorXd& u) {
  ++builds_;
  // the active triangles' boxes, grown by their reach (depth h + skin)
  double largest = 0.0;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    if (!face_active_[triangles_[t].face]) continue;
    const Triangle& tri = triangles_[t];
    Vec3 a = position(u, tri.nodes[0]), b = a;
    for (int c = 1; c < 3; ++c) {
      const Vec3 x = position(u, tri.nodes[static_cast<std::size_t>(c)]);
      a = a.cwiseMin(x);
      b = b.cwiseMax(x);
    }
    const double reach = tri.depth + skin_;
    a.array() -= reach;
    b.array() += reach;
    boxes_[t] = {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()};
    largest = std::max(largest, (b - a).maxCoeff());
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  for (std::size_t j = 0; j < nodes_.size(); ++j) x_built_[j] = position(u, nodes_[j]);
  candidates_.clear();
  std::fill(start_.begin(), start_.end(), 0);
  if (!(largest > 0.0)) return;  // no face in contact
  // a uniform grid of cells at least as large as any box: each box in at most 8 cells; no more
  // cells than a few per triangle
  double cell = largest;
  const Vec3 extent = hi - lo;
  auto dims = [&](double c) {
    return std::array<long, 3>{static_cast<long>(extent.x() / c) + 1, static_cast<long>(extent.y() / c) + 1,
                               static_cast<long>(extent.z() / c) + 1};
  };
  auto d = dims(cell);
  const double limit = 8.0 * static_cast<double>(triangles_.size()) + 64.0;
  while (static_cast<double>(d[0]) * static_cast<double>(d[1]) * static_cast<double>(d[2]) > limit) {
    cell *= 1.5;
    d = dims(cell);
  }
  const auto cell_of = [&](double x, double origin, long n) {
    return std::clamp(static_cast<long>((x - origin) / cell), 0L, n - 1);
  };
  const std::size_t cells = static_cast<std::size_t>(d[0] * d[1] * d[2]);
  cell_start_.assign(cells + 1, 0);
  // a counting sort of the triangles by cell: count, offsets, fill
  const auto for_cells = [&](std::size_t t, auto&& visit) {
    const auto& b = boxes_[t];
    for (long i = cell_of(b[0], lo.x(), d[0]); i <= cell_of(b[3], lo.x(), d[0]); ++i)
      for (long k = cell_of(b[1], lo.y(), d[1]); k <= cell_of(b[4], lo.y(), d[1]); ++k)
        for (long l = cell_of(b[2], lo.z(), d[2]); l <= cell_of(b[5], lo.z(), d[2]); ++l)
          visit(static_cast<std::size_t>((l * d[1] + k) * d[0] + i));
  };
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    if (face_active_[triangles_[t].face]) for_cells(t, [&](std::size_t c) { ++cell_start_[c + 1]; });
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(cell_start_[cells]);
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    if (face_active_[triangles_[t].face]) for_cells(t, [&](std::size_t c) { cell_items_[cell_fill_[c]++] = t; });
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    start_[j] = candidates_.size();
    if (!(k_node_[j] > 0.0)) continue;
    const Vec3& x = x_built_[j];
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
    const auto c = static_cast<std::size_t>(
        (cell_of(x.z(), lo.z(), d[2]) * d[1] + cell_of(x.y(), lo.y(), d[1])) * d[0] +
        cell_of(x.x(), lo.x(), d[0]));
    const std::size_t first = candidates_.size();
    const std::size_t node = nodes_[j];
    for (std::size_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) {
      const std::size_t t = cell_items_[i];
      const auto& b = boxes_[t];
      if (x.x() < b[0] || x.y() < b[1] || x.z() < b[2] || x.x() > b[3] || x.y() > b[4] || x.z() > b[5])
        continue;
      const Triangle& tri = triangles_[t];
      if (has_node(mesh_.element(face_owner_[tri.face]), node)) continue;
      const auto cp = geometry::closest_point_on_triangle(x, position(u, tri.nodes[0]),
                                                          position(u, tri.nodes[1]),
                                                          position(u, tri.nodes[2]));
      if ((cp.point - x).norm() > tri.depth + skin_) continue;
      candidates_.push_back(t);
    }
    std::sort(candidates_.begin() + static_cast<std::ptrdiff_t>(first), candidates_.end());
  }
  start_[nodes_.size()] = candidates_.size();
}

void SelfContact::add(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseMatrix* k,
                      const BlockAssembler& /*assembler*/) {
  if (k != nullptr)
    throw Error("self contact '" + name_ + "' offers no tangent: it works in central-difference "
                "(explicit) analyses only");
  const bool refreshed = refresh_;
  if (refresh_) {
    update_active();
    build_list(u);
    refresh_ = false;
  } else {
    // the Verlet list holds while no contact node has moved half the skin since it was built
    const double half2 = 0.25 * skin_ * skin_;
    for (std::size_t j = 0; j < nodes_.size(); ++j)
      if (k_node_[j] > 0.0 && (position(u, nodes_[j]) - x_built_[j]).squaredNorm() > half2) {
        build_list(u);
        break;
      }
  }
  energy_ = force_sum_ = 0.0;
  active_ = 0;
  std::fill(pre_trial_.begin(), pre_trial_.end(), 0.0);
  std::fill(held_trial_.begin(), held_trial_.end(), triangles_.size());
  for (std::size_t j = 0; j < nodes_.size(); ++j) x_trial_[j] = position(u, nodes_[j]);
  double round_off2 = 0.0;
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    if (start_[j] == start_[j + 1]) continue;
    const std::size_t node = nodes_[j];
    const Vec3& x = x_trial_[j];
    // each candidate's plane: normal, signed distance, barycentric coordinates of the projection
    // and how far outside the triangle that lies (0 inside; in units of its size)
    const std::size_t count = start_[j + 1] - start_[j];
    if (probe_.size() < count) probe_.resize(count);  // grows to the largest list, then stays
    for (std::size_t i = 0; i < count; ++i) {
      const Triangle& tri = triangles_[candidates_[start_[j] + i]];
      Probe& pr = probe_[i];
      const Vec3 a = position(u, tri.nodes[0]), b = position(u, tri.nodes[1]), c = position(u, tri.nodes[2]);
      Vec3 n = (b - a).cross(c - a);
      const double twice_area = n.norm();
      pr.valid = twice_area > 0.0;
      if (!pr.valid) continue;
      n /= twice_area;
      pr.normal = n;
      pr.gap = n.dot(x - a);
      const Vec3 q = x - pr.gap * n;
      pr.weights[0] = n.dot((b - q).cross(c - q)) / twice_area;
      pr.weights[1] = n.dot((c - q).cross(a - q)) / twice_area;
      pr.weights[2] = 1.0 - pr.weights[0] - pr.weights[1];
      pr.outside = -std::min({pr.weights[0], pr.weights[1], pr.weights[2], 0.0});
      pr.size = std::sqrt(twice_area);
    }
    // a node in front of a face's plane lies outside the face's element (a convex cell lies
    // behind all its faces' planes): the element's other faces, behind whose planes it may lie
    // (beside a convex edge), do not touch it
    for (std::size_t i = 0; i < count; ++i) probe_[i].owner_outside = false;
    for (std::size_t i = 0; i < count; ++i) {
      if (!probe_[i].valid || !(probe_[i].gap >= 0.0)) continue;
      const std::size_t owner = face_owner_[triangles_[candidates_[start_[j] + i]].face];
      for (std::size_t other = 0; other < count; ++other)
        if (face_owner_[triangles_[candidates_[start_[j] + other]].face] == owner)
          probe_[other].owner_outside = true;
    }
    // of the faces it lies behind (within their depth) and projects onto, the nearest plane (the
    // face it has just passed), the first on a tie. "Onto" up to a margin of |g| / size: the
    // gap that two triangles meeting at a convex kink (a warped quadrilateral's diagonal, the
    // edge between two faces) leave between their projections grows with the depth as |g|
    // times the kink's angle
    std::size_t best = count;
    for (std::size_t i = 0; i < count; ++i) {
      const Probe& pr = probe_[i];
      const Triangle& tri = triangles_[candidates_[start_[j] + i]];
      if (!pr.valid || pr.owner_outside || !(pr.gap < 0.0 && pr.gap > -tri.depth)) continue;
      if (pr.outside > 1e-9 + -pr.gap / pr.size) continue;
      if (best < count && !(-pr.gap < -probe_[best].gap)) continue;
      best = i;
    }
    if (best == count) continue;
    const Probe& pr = probe_[best];
    const Triangle& tri = triangles_[candidates_[start_[j] + best]];
    // pre-penetration: a face that has just joined (erosion exposed it) finds the node where it
    // is and pushes only beyond that depth; the depth is followed down as the node comes out
    const double depth = -pr.gap;
    const bool fresh = refreshed && !face_active_committed_[tri.face];
    double pre = fresh ? std::max(pre_[j], depth) : std::min(pre_[j], depth);
    const std::size_t t = candidates_[start_[j] + best];
    if (!fresh && held_[j] != t) {
      // a triangle it did not touch at the last committed configuration: the overlap then
      // (with the triangle it touched, or none) plus its approach to this one since
      const auto depth_then = [&](const Triangle& s) {
        const Vec3& a0 = x_committed_[node_slot_[s.nodes[0]]];
        const Vec3 n0 = (x_committed_[node_slot_[s.nodes[1]]] - a0)
                            .cross(x_committed_[node_slot_[s.nodes[2]]] - a0);
        const double area0 = n0.norm();
        return area0 > 0.0 ? -n0.dot(x_committed_[j] - a0) / area0 : 0.0;
      };
      const double overlap_then =
          held_[j] < triangles_.size() ? std::max(depth_then(triangles_[held_[j]]) - pre_[j], 0.0) : 0.0;
      pre = std::clamp(depth_then(tri) - overlap_then, 0.0, depth);
    }
    pre_trial_[j] = pre;
    held_trial_[j] = t;
    const double overlap = depth - pre;
    if (!(overlap > 0.0)) continue;
    ++active_;
    const double kn = k_node_[j];
    // p = k (|g| - pre) n on the node, -l_i p on the triangle's corners (the weights clamped to
    // the triangle where the projection lies within the margin outside); W = 1/2 k (|g| - pre)^2
    const Vec3 p = kn * overlap * pr.normal;
    std::array<double, 3> w{std::max(pr.weights[0], 0.0), std::max(pr.weights[1], 0.0),
                            std::max(pr.weights[2], 0.0)};
    const double sum = w[0] + w[1] + w[2];
    f.segment<3>(3 * static_cast<Eigen::Index>(node)) -= p;
    for (std::size_t c = 0; c < 3; ++c)
      f.segment<3>(3 * static_cast<Eigen::Index>(tri.nodes[c])) += (w[c] / sum) * p;
    energy_ += 0.5 * kn * overlap * overlap;
    force_sum_ += p.norm();
    const double scale = kn * (x.norm() + depth) + p.norm();
    round_off2 += scale * scale;
  }
  round_off_ = std::numeric_limits<double>::epsilon() * std::sqrt(round_off2);
  if (refreshed) {  // at the committed configuration: its depths and faces are the committed ones
    pre_ = pre_trial_;
    face_active_committed_ = face_active_;
    held_ = held_trial_;
    x_committed_ = x_trial_;
  }
}

void SelfContact::commit() {
  pre_.swap(pre_trial_);
  held_.swap(held_trial_);
  x_committed_.swap(x_trial_);
}

// [pre-penetration per node][face took part per face][triangle touched per node (the count of
// triangles: none)][position per node, x y z]
const std::vector<double>& SelfContact::committed_state() const {
  state_.assign(pre_.begin(), pre_.end());
  for (const char a : face_active_committed_) state_.push_back(a ? 1.0 : 0.0);
  for (const std::size_t t : held_) state_.push_back(static_cast<double>(t));
  for (const Vec3& x : x_committed_) state_.insert(state_.end(), {x.x(), x.y(), x.z()});
  return state_;
}

void SelfContact::set_committed_state(const std::vector<double>& state) {
  const std::size_t n = nodes_.size(), expected = 5 * n + faces_.size();
  if (state.size() != expected)
    throw Error("self contact '" + name_ + "': a state of " + std::to_string(state.size()) +
                " values was given, it keeps " + std::to_string(expected));
  std::copy(state.begin(), state.begin() + static_cast<std::ptrdiff_t>(n), pre_.begin());
  for (std::size_t f = 0; f < faces_.size(); ++f)
    face_active_committed_[f] = state[n + f] != 0.0 ? 1 : 0;
  const std::size_t held_at = n + faces_.size(), x_at = held_at + n;
  for (std::size_t j = 0; j < n; ++j) {
    const double t = state[held_at + j];
    if (!(t >= 0.0 && t <= static_cast<double>(triangles_.size())))
      throw Error("self contact '" + name_ + "': the state names triangle " + std::to_string(t) +
                  " of " + std::to_string(triangles_.size()));
    held_[j] = static_cast<std::size_t>(t);
    x_committed_[j] = Vec3(state[x_at + 3 * j], state[x_at + 3 * j + 1], state[x_at + 3 * j + 2]);
  }
  pre_trial_ = pre_;
  held_trial_ = held_;
  x_trial_ = x_committed_;
  refresh_ = true;
}

double SelfContact::max_frequency_squared(const Eigen::VectorXd& nodal_mass) const {
  double w = 0.0;
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    const double m = nodal_mass[static_cast<Eigen::Index>(nodes_[j])];
    if (m > 0.0) w = std::max(w, k_bound_[j] / m);
  }
  return 4.0 * w;
}

}  // namespace partita::fem
