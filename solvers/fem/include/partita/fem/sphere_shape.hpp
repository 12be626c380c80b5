#pragma once
#include "partita/fem/rigid_shape.hpp"

namespace partita::fem {

// A rigid sphere of radius r about centre c: g(x) = |x - c| - r, n = (x - c) / |x - c|.
class SphereShape final : public RigidShape {
 public:
  // Throws Error unless radius > 0 and finite.
  SphereShape(const Vec3& centre, double radius);
  std::string_view kind() const override { return "sphere"; }
  ShapeDistance distance(const Vec3& x) const override;
  // An icosahedron subdivided `levels` times, projected on the sphere.
  SurfaceTriangulation triangulate() const override;
  const Vec3& centre() const { return centre_; }
  double radius() const { return radius_; }

 private:
  Vec3 centre_;
  double radius_;
};

}  // namespace partita::fem
