#pragma once
#include "partita/fem/rigid_shape.hpp"

namespace partita::fem {

// A rigid capsule: the points within radius r of the segment from c - L/2 a to c + L/2 a (a
// cylinder of length L with a hemispherical cap at each end; a bulbous bow). With s the segment's
// point closest to x: g(x) = |x - s| - r, n = (x - s) / |x - s|. L = 0 is a sphere.
class CapsuleShape final : public RigidShape {
 public:
  // Throws Error unless radius > 0, length >= 0 and the axis is not zero.
  CapsuleShape(const Vec3& centre, const Vec3& axis, double length, double radius);
  std::string_view kind() const override { return "capsule"; }
  ShapeDistance distance(const Vec3& x) const override;
  SurfaceTriangulation triangulate() const override;

 private:
  Vec3 centre_, axis_;  // axis_ unit
  double half_length_, radius_;
};

}  // namespace partita::fem
