#include "partita/fem/capsule_shape.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

CapsuleShape::CapsuleShape(const Vec3& centre, const Vec3& axis, double length, double radius)
    : centre_(centre), half_length_(0.5 * length), radius_(radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw Error("capsule: the radius must be > 0, got " + std::to_string(radius));
  if (!(length >= 0.0) || !std::isfinite(length))
    throw Error("capsule: the length must be >= 0, got " + std::to_string(length));
  if (!(axis.norm() > 0.0) || !axis.allFinite())
    throw Error("capsule: the axis must be a non-zero vector");
  axis_ = axis.normalized();
}

ShapeDistance CapsuleShape::distance(const Vec3& x) const {
  // s = c + clamp((x - c) . a, -L/2, L/2) a;  g = |x - s| - r,  n = (x - s) / |x - s|
  const double along = std::clamp((x - centre_).dot(axis_), -half_length_, half_length_);
  const Vec3 d = x - (centre_ + along * axis_);
  const double r = d.norm();
  if (r > 0.0) return {r - radius_, d / r};
  // on the axis: any direction normal to it
  const Vec3 any = axis_.unitOrthogonal();
  return {-radius_, any};
}

SurfaceTriangulation CapsuleShape::triangulate() const {
  // rings of 24 points around the axis: 6 latitude rings per cap plus the two ends of the
  // cylinder, and a pole at each end
  constexpr int kAround = 24, kCap = 6;
  const Vec3 e1 = axis_.unitOrthogonal(), e2 = axis_.cross(e1);
  SurfaceTriangulation s;
  s.vertices.push_back(centre_ - (half_length_ + radius_) * axis_);  // pole at -a
  std::vector<std::pair<double, double>> rings;  // (offset along a, ring radius)
  for (int i = 1; i <= kCap; ++i) {
    const double phi = 0.5 * std::numbers::pi * i / kCap;  // from the pole
    rings.emplace_back(-half_length_ - radius_ * std::cos(phi), radius_ * std::sin(phi));
  }
  for (int i = kCap - 1; i >= 1; --i) {
    const double phi = 0.5 * std::numbers::pi * i / kCap;
    rings.emplace_back(half_length_ + radius_ * std::cos(phi), radius_ * std::sin(phi));
  }
  if (half_length_ > 0.0) rings.insert(rings.begin() + kCap, {half_length_, radius_});
  for (const auto& [z, r] : rings) {
    for (int k = 0; k < kAround; ++k) {
      const double th = 2.0 * std::numbers::pi * k / kAround;
      s.vertices.push_back(centre_ + z * axis_ + r * (std::cos(th) * e1 + std::sin(th) * e2));
    }
  }
  s.vertices.push_back(centre_ + (half_length_ + radius_) * axis_);  // pole at +a
  const int last = static_cast<int>(s.vertices.size()) - 1;
  const int nr = static_cast<int>(rings.size());
  auto ring = [&](int i, int k) { return 1 + i * kAround + (k % kAround); };
  // outward orientation: e1 x e2 = a, so increasing k turns counter-clockwise about +a
  for (int k = 0; k < kAround; ++k) s.triangles.push_back({0, ring(0, k + 1), ring(0, k)});
  for (int i = 0; i + 1 < nr; ++i) {
    for (int k = 0; k < kAround; ++k) {
      s.triangles.push_back({ring(i, k), ring(i, k + 1), ring(i + 1, k + 1)});
      s.triangles.push_back({ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)});
    }
  }
  for (int k = 0; k < kAround; ++k) s.triangles.push_back({last, ring(nr - 1, k), ring(nr - 1, k + 1)});
  return s;
}

}  // namespace partita::fem
