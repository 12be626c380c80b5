#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "partita/fem/rigid_shape.hpp"

namespace partita::fem {

// A rigid body bounded by a closed triangulated surface (an STL hull, counter-clockwise seen from
// outside). Signed distance: the distance to the nearest triangle, its sign from the
// angle-weighted pseudo-normal of the nearest feature (face, edge or vertex; Baerentzen & Aanaes,
// IEEE TVCG 11, 2005, 243-253), which gives the right sign for any closed, consistently oriented
// surface; the normal is (x - closest) / |x - closest| turned outward (the face normal where the
// point lies on the surface).
// Search: a uniform grid of cells of edge >= search_radius over the surface's bounding box (at
// most 64 cells along an edge); each triangle is listed in every cell its box, grown by the
// search radius, touches. A query reads the one cell x lies in: points farther than the search
// radius from the surface get gap = search_radius (not in contact), so penetrations deeper than
// it are missed (choose it a few times the expected penetration; contact penetrations are small).
// Cost per query: the triangles of one cell.
class TriangulatedShape final : public RigidShape {
 public:
  // Throws Error for an empty surface, an index out of range, a degenerate triangle, or
  // search_radius <= 0.
  TriangulatedShape(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles,
                    double search_radius);
  std::string_view kind() const override { return "surface"; }
  ShapeDistance distance(const Vec3& x) const override;
  SurfaceTriangulation triangulate() const override { return {vertices_, triangles_}; }
  double search_radius() const { return search_radius_; }
  // The largest number of triangles a query tests (the fullest cell's list).
  std::size_t max_cell_triangles() const;

 private:
  // The cell holding x; false when x lies outside the grid (farther than the search radius).
  bool cell_of(const Vec3& x, std::size_t& cell) const;
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec3> face_normal_;                  // unit, per triangle
  std::vector<Vec3> vertex_normal_;                // angle-weighted pseudo-normals
  std::vector<std::array<Vec3, 3>> edge_normal_;   // per triangle edge (v0v1, v1v2, v2v0)
  double search_radius_;
  Vec3 lo_;
  double cell_size_ = 1.0;
  std::array<long, 3> dims_{1, 1, 1};
  std::vector<std::size_t> cell_start_;  // CSR over cells
  std::vector<int> cells_;
};

}  // namespace partita::fem
