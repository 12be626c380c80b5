#pragma once
// The point of a triangle closest to a query point (Ericson, Real-Time Collision Detection,
// 2005, section 5.1.5): the Voronoi regions of the vertices, the edges and the face are tested in
// turn, from dot products of the edges with the vectors to the point; outside the triangle's
// prism the answer clamps to the nearest edge or vertex. Header-only, Eigen alone: the DEM's
// triangle-mesh contacts, the FE solver's triangulated surfaces and the coupling's
// nearest-projection mapper all take it from here (partita::geometry).

#include <array>

#include <Eigen/Core>

namespace partita::geometry {

/// Closest point of a triangle (a, b, c) to a point, with the feature it lies on.
struct TriangleClosestPoint {
  enum Feature { face = 0, edge = 1, vertex = 2 };
  Eigen::Vector3d point;
  /// Weights of a, b, c: point = l0 a + l1 b + l2 c (up to rounding), l_k >= 0, sum 1.
  std::array<double, 3> barycentric;
  Feature feature = face;
  /// vertex 0 (a), 1 (b), 2 (c); edge 0 (ab), 1 (bc), 2 (ca); face 0.
  int local_index = 0;
};

/// The point of triangle (a, b, c) closest to p. The triangle must have area > 0 (a degenerate
/// one divides by zero on the face or an edge).
inline TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p,
                                                      const Eigen::Vector3d& a,
                                                      const Eigen::Vector3d& b,
                                                      const Eigen::Vector3d& c) {
  TriangleClosestPoint r;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {  // vertex a
    r.point = a, r.barycentric = {1.0, 0.0, 0.0}, r.feature = r.vertex, r.local_index = 0;
    return r;
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {  // vertex b
    r.point = b, r.barycentric = {0.0, 1.0, 0.0}, r.feature = r.vertex, r.local_index = 1;
    return r;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {  // edge ab
    const double v = d1 / (d1 - d3);
    r.point = a + v * ab, r.barycentric = {1.0 - v, v, 0.0}, r.feature = r.edge;
    r.local_index = 0;
    return r;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {  // vertex c
    r.point = c, r.barycentric = {0.0, 0.0, 1.0}, r.feature = r.vertex, r.local_index = 2;
    return r;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {  // edge ca
    const double w = d2 / (d2 - d6);
    r.point = a + w * ac, r.barycentric = {1.0 - w, 0.0, w}, r.feature = r.edge;
    r.local_index = 2;
    return r;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge bc
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    r.point = b + w * (c - b), r.barycentric = {0.0, 1.0 - w, w}, r.feature = r.edge;
    r.local_index = 1;
    return r;
  }
  // inside: the orthogonal projection onto the plane
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  r.point = a + v * ab + w * ac, r.barycentric = {1.0 - v - w, v, w}, r.feature = r.face;
  r.local_index = 0;
  return r;
}

}  // namespace partita::geometry
