#include "partita/fem/sphere_shape.hpp"

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "partita/fem/error.hpp"

namespace partita::fem {

SphereShape::SphereShape(const Vec3& centre, double radius) : centre_(centre), radius_(radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    throw Error("sphere: the radius must be > 0, got " + std::to_string(radius));
}

ShapeDistance SphereShape::distance(const Vec3& x) const {
  // g = |x - c| - r,  n = (x - c) / |x - c|
  const Vec3 d = x - centre_;
  const double r = d.norm();
  return {r - radius_, r > 0.0 ? Vec3(d / r) : Vec3(Vec3::UnitZ())};
}

SurfaceTriangulation SphereShape::triangulate() const {
  // icosahedron, each triangle split in 4 twice (320 triangles), vertices on the sphere
  const double p = 0.5 * (1.0 + std::sqrt(5.0));
  std::vector<Vec3> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                         {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  std::vector<std::array<int, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& x : v) x.normalize();
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : t) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    t = std::move(next);
  }
  for (auto& x : v) x = centre_ + radius_ * x;
  return {std::move(v), std::move(t)};
}

}  // namespace partita::fem
