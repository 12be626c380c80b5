#include "partita/dem/triangle_mesh.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace partita::dem {

TriangleMesh::TriangleMesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices,
                           const Triangles& triangles, int material)
    : material_(material) {
  const int nv = static_cast<int>(vertices.rows());
  if (nv < 3 || triangles.rows() < 1) {
    std::ostringstream msg;
    msg << "add_mesh: need at least 3 vertices and 1 triangle, got " << nv << " vertices and "
        << triangles.rows() << " triangles";
    throw Error(msg.str());
  }
  position_.resize(nv);
  for (int v = 0; v < nv; ++v) {
    position_[v] = vertices.row(v).transpose();
    if (!position_[v].allFinite()) {
      std::ostringstream msg;
      msg << "add_mesh: vertex " << v << " has a non-finite coordinate";
      throw Error(msg.str());
    }
  }
  velocity_.assign(nv, Eigen::Vector3d::Zero());
  position_last_step_ = position_;
  position_at_build_ = position_;
  std::map<std::pair<int, int>, int> edge_id;
  for (int t = 0; t < triangles.rows(); ++t) {
    std::array<int, 3> tri{triangles(t, 0), triangles(t, 1), triangles(t, 2)};
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= nv) {
        std::ostringstream msg;
        msg << "add_mesh: triangle " << t << " refers to vertex " << tri[k]
            << ", allowed indices are 0.." << nv - 1;
        throw Error(msg.str());
      }
    const Eigen::Vector3d nrm =
        (position_[tri[1]] - position_[tri[0]]).cross(position_[tri[2]] - position_[tri[0]]);
    if (!(nrm.norm() > 0.0)) {
      std::ostringstream msg;
      msg << "add_mesh: triangle " << t << " (" << tri[0] << ", " << tri[1] << ", " << tri[2]
          << ") is degenerate (zero area)";
      throw Error(msg.str());
    }
    std::array<int, 3> te{};
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = edge_id.find(key);
      if (it == edge_id.end()) {
        it = edge_id.emplace(key, static_cast<int>(edges_.size())).first;
        edges_.push_back({key.first, key.second});
      }
      te[k] = it->second;
    }
    triangles_.push_back(tri);
    triangle_edges_.push_back(te);
  }
  triangle_force_ = Eigen::MatrixX3d::Zero(triangle_count(), 3);
  vertex_force_ = Eigen::MatrixX3d::Zero(nv, 3);
  vertex_triangles_.assign(nv, 0);
  for (const auto& tri : triangles_)
    for (int v : tri) ++vertex_triangles_[v];
  vertex_share_.assign(nv, 0.0);
  for (int v = 0; v < nv; ++v)
    if (vertex_triangles_[v] > 0) vertex_share_[v] = 1.0 / vertex_triangles_[v];

  // Topology for the local-closest test: opposite vertices of each edge, neighbours of each
  // vertex (compressed rows).
  const int ne = static_cast<int>(edges_.size());
  edge_opposite_offset_.assign(ne + 1, 0);
  vertex_neighbor_offset_.assign(nv + 1, 0);
  for (const auto& te : triangle_edges_)
    for (int e : te) ++edge_opposite_offset_[e + 1];
  for (const auto& e : edges_)
    ++vertex_neighbor_offset_[e[0] + 1], ++vertex_neighbor_offset_[e[1] + 1];
  for (int e = 0; e < ne; ++e) edge_opposite_offset_[e + 1] += edge_opposite_offset_[e];
  for (int v = 0; v < nv; ++v) vertex_neighbor_offset_[v + 1] += vertex_neighbor_offset_[v];
  edge_opposite_.resize(edge_opposite_offset_[ne]);
  edge_opposite_triangle_.resize(edge_opposite_.size());
  vertex_neighbor_.resize(vertex_neighbor_offset_[nv]);
  vertex_neighbor_edge_.resize(vertex_neighbor_.size());
  std::vector<int> fill(edge_opposite_offset_.begin(), edge_opposite_offset_.end() - 1);
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int at = fill[triangle_edges_[t][k]]++;
      edge_opposite_[at] = triangles_[t][(k + 2) % 3];
      edge_opposite_triangle_[at] = static_cast<int>(t);
    }
  fill.assign(vertex_neighbor_offset_.begin(), vertex_neighbor_offset_.end() - 1);
  for (int e = 0; e < ne; ++e) {
    vertex_neighbor_edge_[fill[edges_[e][0]]] = e;
    vertex_neighbor_[fill[edges_[e][0]]++] = edges_[e][1];
    vertex_neighbor_edge_[fill[edges_[e][1]]] = e;
    vertex_neighbor_[fill[edges_[e][1]]++] = edges_[e][0];
  }
  active_.assign(triangles_.size(), 1);
}

void TriangleMesh::set_triangle_active(int t, bool active) {
  if (t < 0 || t >= triangle_count()) {
    std::ostringstream msg;
    msg << "set_triangle_active: triangle " << t << " of a mesh of " << triangle_count()
        << " triangles";
    throw Error(msg.str());
  }
  if ((active_[t] != 0) == active) return;
  active_[t] = active ? 1 : 0;
  if (active) {
    if (fresh_.empty()) fresh_.assign(triangles_.size(), 0);
    if (fresh_[t] == 0) fresh_[t] = 1, ++fresh_count_;
  }
  inactive_ += active ? -1 : 1;
  // a vertex's force is shared among the active triangles that have it (a vertex with force
  // has one: the contacts touch active triangles only)
  for (int v : triangles_[t]) {
    vertex_triangles_[v] += active ? 1 : -1;
    vertex_share_[v] = vertex_triangles_[v] > 0 ? 1.0 / vertex_triangles_[v] : 0.0;
  }
}

void TriangleMesh::clear_fresh() {
  if (fresh_count_ == 0) return;
  std::fill(fresh_.begin(), fresh_.end(), 0);
  fresh_count_ = 0;
}

bool TriangleMesh::feature_is_local_closest(int t, const TriangleClosestPoint& cp,
                                            const Eigen::Vector3d& p) const {
  if (cp.feature == TriangleClosestPoint::face) return true;
  const Eigen::Vector3d d = p - cp.point;
  const double dn = d.norm();
  if (dn == 0.0) return true;  // on the surface
  // A neighbouring triangle is nearer than the feature when p lies beyond the feature's
  // boundary with it: d . (w - feature) > 0 for a vertex w of that triangle off the feature
  // (the Voronoi tests of closest_point, seen from the feature). The tolerance keeps a point
  // exactly over a shared edge of coplanar triangles a contact of that edge.
  constexpr double tol = 1e-9;
  if (cp.feature == TriangleClosestPoint::edge) {
    const int e = triangle_edges_[t][cp.local_index];
    const Eigen::Vector3d& a = position_[edges_[e][0]];
    for (int k = edge_opposite_offset_[e]; k < edge_opposite_offset_[e + 1]; ++k) {
      if (!triangle_active(edge_opposite_triangle_[k])) continue;
      const Eigen::Vector3d w = position_[edge_opposite_[k]] - a;
      if (d.dot(w) > tol * dn * w.norm()) return false;
    }
    return true;
  }
  const int v = triangles_[t][cp.local_index];
  const Eigen::Vector3d& a = position_[v];
  // (an edge only of inactive triangles is no part of the surface)
  const auto edge_active = [&](int e) {
    if (inactive_ == 0) return true;
    for (int k = edge_opposite_offset_[e]; k < edge_opposite_offset_[e + 1]; ++k)
      if (active_[edge_opposite_triangle_[k]] != 0) return true;
    return false;
  };
  for (int k = vertex_neighbor_offset_[v]; k < vertex_neighbor_offset_[v + 1]; ++k) {
    if (!edge_active(vertex_neighbor_edge_[k])) continue;
    const Eigen::Vector3d w = position_[vertex_neighbor_[k]] - a;
    if (d.dot(w) > tol * dn * w.norm()) return false;
  }
  return true;
}

TriangleClosestPoint TriangleMesh::closest_point(int t, const Eigen::Vector3d& p) const {
  return geometry::closest_point_on_triangle(
      p, position_[triangles_[t][0]], position_[triangles_[t][1]], position_[triangles_[t][2]]);
}

Eigen::Vector3d TriangleMesh::normal(int t) const {
  const auto& tri = triangles_[t];
  return (position_[tri[1]] - position_[tri[0]])
      .cross(position_[tri[2]] - position_[tri[0]])
      .normalized();
}

double TriangleMesh::overlap(int t, const Eigen::Vector3d& p, double r, bool* behind) const {
  const TriangleClosestPoint cp = closest_point(t, p);
  if (behind) *behind = false;
  if (!one_sided_) return r - (p - cp.point).norm();
  const double s = (p - cp.point).dot(normal(t));
  if (s >= 0.0) return r - (p - cp.point).norm();
  // behind the plane: a face (or the point projects onto the triangle's edge), < r deep
  if ((p - cp.point).squaredNorm() - s * s > 1e-12 * r * r || s <= -r) return 0.0;
  if (behind) *behind = true;
  return r - s;
}

void TriangleMesh::write_state(BinaryWriter& out) const {
  out.value(static_cast<std::int64_t>(vertex_count()));
  out.value(static_cast<std::int64_t>(triangle_count()));
  out.array(position_);
  out.array(velocity_);
  out.array(position_last_step_);
  out.array(position_at_build_);
  const std::vector<double> tf(triangle_force_.data(),
                               triangle_force_.data() + triangle_force_.size());
  const std::vector<double> vf(vertex_force_.data(), vertex_force_.data() + vertex_force_.size());
  out.array(tf);
  out.array(vf);
  out.value(static_cast<char>(velocity_from_motion_));
}

void TriangleMesh::read_state(BinaryReader& in) {
  in.expect(static_cast<std::int64_t>(vertex_count()), "mesh vertex count");
  in.expect(static_cast<std::int64_t>(triangle_count()), "mesh triangle count");
  in.array(position_, "mesh vertex positions");
  in.array(velocity_, "mesh vertex velocities");
  in.array(position_last_step_, "mesh positions of the last step");
  in.array(position_at_build_, "mesh positions at the list build");
  std::vector<double> tf, vf;
  in.array(tf, "mesh triangle forces");
  in.array(vf, "mesh vertex forces");
  if (tf.size() != static_cast<std::size_t>(triangle_force_.size()) ||
      vf.size() != static_cast<std::size_t>(vertex_force_.size()) ||
      position_.size() != static_cast<std::size_t>(vertex_count()))
    throw Error("corrupt state: mesh arrays do not match the mesh");
  std::copy(tf.begin(), tf.end(), triangle_force_.data());
  std::copy(vf.begin(), vf.end(), vertex_force_.data());
  velocity_from_motion_ = in.value<char>("mesh velocity mode") != 0;
}

}  // namespace partita::dem
