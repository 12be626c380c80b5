#pragma once
#include <array>
#include <string_view>
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem {

// Where a point lies relative to a rigid surface: the signed distance (negative inside the body,
// i.e. a penetration) and the body's outward unit normal at the closest surface point.
struct ShapeDistance {
  double gap = 0.0;
  Vec3 normal = Vec3::UnitZ();
};

// A triangulated picture of a rigid surface (output, or a moving mesh for other solvers).
struct SurfaceTriangulation {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// The geometry of a rigid indenter (RigidIndenter) in its initial position: a sphere, a capsule,
// a half-space or a closed triangulated surface. The indenter translates it; distance() is asked
// at x - d, d the indenter's displacement. Immutable once built (thread-safe queries).
class RigidShape {
 public:
  virtual ~RigidShape() = default;
  virtual std::string_view kind() const = 0;
  // Signed distance of x and the outward normal. Shapes that search locally (a triangulated
  // surface) report gap >= search_radius() (not in contact) for points farther than that.
  virtual ShapeDistance distance(const Vec3& x) const = 0;
  // Triangles approximating the surface (empty for an unbounded half-space).
  virtual SurfaceTriangulation triangulate() const { return {}; }
};

}  // namespace partita::fem
