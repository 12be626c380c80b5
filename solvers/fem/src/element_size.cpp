// element_length(): volume over the largest face area (element_size.hpp).
#include "partita/fem/element_size.hpp"

#include "partita/fem/element_topology.hpp"

#include <algorithm>

namespace partita::fem {

double element_length(ElementType type, const ElementCoordinates& x) {
  const int corners = corner_count(type);
  Vec3 centre = Vec3::Zero();
  for (int a = 0; a < corners; ++a) centre += x.row(a).transpose();
  centre /= corners;
  double six_volume = 0.0, largest = 0.0;
  for (int f = 0; f < local_face_count(type); ++f) {
    const auto nodes = local_face_nodes(type, f);
    const int n = local_face_type(type, f) == FaceType::Tri3 || local_face_type(type, f) == FaceType::Tri6 ? 3 : 4;
    Vec3 p[4];
    for (int k = 0; k < n; ++k) p[k] = x.row(nodes[static_cast<std::size_t>(k)]).transpose() - centre;
    if (n == 3) {
      six_volume += p[0].dot(p[1].cross(p[2]));
      largest = std::max(largest, 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm());
      continue;
    }
    const Vec3 c = 0.25 * (p[0] + p[1] + p[2] + p[3]);
    double area = 0.0;
    for (int k = 0; k < 4; ++k) {
      const Vec3& a = p[k];
      const Vec3& b = p[(k + 1) % 4];
      six_volume += c.dot(a.cross(b));
      area += 0.5 * (a - c).cross(b - c).norm();
    }
    largest = std::max(largest, area);
  }
  const double volume = six_volume / 6.0;
  return volume > 0.0 && largest > 0.0 ? volume / largest : 0.0;
}

}  // namespace partita::fem
