#pragma once
// A triangle mesh wall whose vertices a caller may move at every step (the coupling interface).
// Holds vertex positions and velocities, edge topology (to count a contact on a shared edge or
// vertex once), and the contact forces of the last step per triangle and per vertex.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "partita/geometry/closest_point.hpp"

namespace partita::dem {

/// Closest point of a triangle to a point, with the feature it lies on (partita::geometry).
using TriangleClosestPoint = geometry::TriangleClosestPoint;

class TriangleMesh {
 public:
  using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3>;

  /// Throws Error if an index is out of range, a triangle is degenerate or a coordinate is not
  /// finite.
  TriangleMesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices, const Triangles& triangles,
               int material);

  int vertex_count() const { return static_cast<int>(position_.size()); }
  int triangle_count() const { return static_cast<int>(triangles_.size()); }
  int material() const { return material_; }
  const std::vector<Eigen::Vector3d>& positions() const { return position_; }
  const std::vector<Eigen::Vector3d>& velocities() const { return velocity_; }
  /// The velocity of triangle t's point of barycentric weights b (a contact point):
  /// b0 v0 + b1 v1 + b2 v2.
  Eigen::Vector3d velocity_at(int t, const std::array<double, 3>& b) const {
    const auto& tri = triangles_[t];
    return b[0] * velocity_[tri[0]] + b[1] * velocity_[tri[1]] + b[2] * velocity_[tri[2]];
  }
  const std::array<int, 3>& triangle(int t) const { return triangles_[t]; }
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  /// Edge ids of triangle t: edges (v0,v1), (v1,v2), (v2,v0).
  const std::array<int, 3>& triangle_edges(int t) const { return triangle_edges_[t]; }
  const std::array<int, 2>& edge(int e) const { return edges_[e]; }

  /// Whether triangle t takes part in contacts (all do at first). A caller takes out a triangle
  /// whose surface is gone (the face of an eroded FE element): no contact detects it, its edges
  /// and vertices act only through the active triangles that share them (the rim of a hole),
  /// and a particle passes where it was.
  bool triangle_active(int t) const { return inactive_ == 0 || active_[t] != 0; }
  void set_triangle_active(int t, bool active);
  /// Whether triangle t entered the contacts (set_triangle_active(t, true) after false) since
  /// the last force pass. A particle that overlaps such a triangle at that pass was there before
  /// the surface was (a face exposed under it): its contact keeps that overlap as its
  /// pre-overlap (MeshContactRecord::pre_overlap) and pushes only beyond it, instead of throwing
  /// the particle out with the energy of the whole overlap at once.
  bool triangle_fresh(int t) const { return fresh_count_ > 0 && fresh_[t] != 0; }
  /// Forgets which triangles entered (System, after each force pass).
  void clear_fresh();
  int inactive_triangle_count() const { return inactive_; }

  /// Whether the contacts are one-sided (off: two-sided, the default). Two-sided, a sphere
  /// touches a triangle from either side and is pushed along centre - closest point. One-sided,
  /// the mesh is the surface of a body (a closed FE surface: triangles counter-clockwise seen
  /// from outside, the body behind them): a face contact pushes along the triangle's outward
  /// normal with overlap r - s (s the centre's signed distance to its plane), so a sphere whose
  /// centre has passed behind the face (less than its radius deep) is pushed back out instead
  /// of on through; an edge or vertex touches only a centre on the outer side of the triangle's
  /// plane (a centre inside the body meets the faces). A thin plate pressed harder than a
  /// sphere's radius no longer lets it through.
  bool one_sided() const { return one_sided_; }
  void set_one_sided(bool on) { one_sided_ = on; }
  /// Unit normal of triangle t (right-hand rule: outward for a one-sided mesh).
  Eigen::Vector3d normal(int t) const;
  /// Overlap of a sphere (centre p, radius r) with triangle t as a contact counts it, <= 0 for
  /// none (two-sided: r - |p - closest point|; one-sided: see one_sided(), *behind set when the
  /// centre is behind the face). Ignores whether the closest point is a local closest point of
  /// the mesh and the choice among several faces a centre is behind (MeshContacts::evaluate()).
  double overlap(int t, const Eigen::Vector3d& p, double r, bool* behind = nullptr) const;

  /// Closest point of triangle t to p (Ericson, Real-Time Collision Detection, 5.1.5).
  TriangleClosestPoint closest_point(int t, const Eigen::Vector3d& p) const;

  /// Whether the closest point `cp` of triangle t to p, found on an edge or vertex, is also the
  /// closest point of every other triangle sharing that edge or vertex, i.e. whether p lies in
  /// the region of the mesh surface that the feature is nearest to. A point over the middle of
  /// a flat mesh is nearest to one face only; the edges and vertices of the other triangles
  /// within reach are not contacts. Faces are always local closest points. Inactive triangles
  /// are no part of the surface here.
  bool feature_is_local_closest(int t, const TriangleClosestPoint& cp,
                                const Eigen::Vector3d& p) const;

  /// Force exerted by the particles on each vertex / triangle in the last step [N]. A contact's
  /// force goes to the vertices of its triangle with the barycentric weights of the contact
  /// point (exact lever rule); a triangle's force is the sum of its vertices' forces, each shared
  /// equally among the active triangles that have the vertex (a triangle taken out gets none:
  /// its surface is gone, the rim of the hole carries the force). Both sum to the total, and both
  /// change continuously as a contact moves across a triangle edge (a contact's whole force put
  /// on the triangle it touches would jump from one triangle to the next: a traction field built
  /// on that made the implicit FEM/DEM windows of the rubber plate stall, 7.8 iterations instead of
  /// 2.1; see cases/uniaxial_compaction/README.md).
  const Eigen::MatrixX3d& triangle_forces() const { return triangle_force_; }
  const Eigen::MatrixX3d& vertex_forces() const { return vertex_force_; }
  Eigen::Vector3d total_force() const { return triangle_force_.colwise().sum().transpose(); }

  /// Writes / reads what changes while stepping (vertex positions and velocities, the last
  /// step's and the last list build's positions, forces); the topology is set-up and must match
  /// (read() throws Error otherwise).
  void write_state(BinaryWriter& out) const;
  void read_state(BinaryReader& in);

 private:
  friend class System;
  friend class NeighborList;
  friend class MeshContacts;

  std::vector<Eigen::Vector3d> position_;
  std::vector<Eigen::Vector3d> velocity_;
  std::vector<Eigen::Vector3d> position_last_step_;  // for velocities from the motion
  std::vector<Eigen::Vector3d> position_at_build_;   // for the neighbour-list criterion
  std::vector<std::array<int, 3>> triangles_;
  std::vector<std::array<int, 3>> triangle_edges_;
  std::vector<std::array<int, 2>> edges_;
  // The vertex opposite edge e in each triangle that has it: edge_opposite_[edge_opposite_offset_
  // [e] .. edge_opposite_offset_[e + 1]); the vertices joined to vertex v by an edge, likewise.
  std::vector<int> edge_opposite_offset_, edge_opposite_;
  std::vector<int> vertex_neighbor_offset_, vertex_neighbor_;
  // the triangle of each edge_opposite_ entry, the edge of each vertex_neighbor_ entry
  std::vector<int> edge_opposite_triangle_, vertex_neighbor_edge_;
  std::vector<char> active_;  // per triangle (see triangle_active())
  int inactive_ = 0;          // triangles not active
  std::vector<char> fresh_;   // per triangle (see triangle_fresh()), sized on first use
  int fresh_count_ = 0;
  std::vector<int> vertex_triangles_;  // the number of active triangles that have the vertex
  std::vector<double> vertex_share_;   // 1 / that number (0 for none)
  Eigen::MatrixX3d triangle_force_;
  Eigen::MatrixX3d vertex_force_;
  int material_ = 0;
  bool velocity_from_motion_ = false;  // next step derives velocities from the displacement
  bool one_sided_ = false;             // see one_sided()
};

}  // namespace partita::dem
