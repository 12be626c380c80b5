#pragma once
#include "partita/fem/rigid_shape.hpp"

namespace partita::fem {

// A rigid half-space {x : (x - p) . n <= 0} bounded by the plane through p with outward unit
// normal n (a flat punch or a rigid floor): g(x) = (x - p) . n, normal n everywhere.
class PlaneShape final : public RigidShape {
 public:
  // Throws Error for a zero normal.
  PlaneShape(const Vec3& point, const Vec3& normal);
  std::string_view kind() const override { return "plane"; }
  ShapeDistance distance(const Vec3& x) const override { return {(x - point_).dot(normal_), normal_}; }

 private:
  Vec3 point_, normal_;
};

}  // namespace partita::fem
