#pragma once
// Where a point lies in an FE mesh (reference configuration): its element and local
// coordinates, for probes and point monitors that sample fields by the element's interpolation
// u(x) = sum_i N_i(xi) u_i.

#include <optional>
#include <utility>
#include <vector>

#include "partita/fem/fem.hpp"

namespace partita::adapters {

struct MeshLocation {
  std::size_t element = 0;
  fem::Vec3 xi = fem::Vec3::Zero();
};

class MeshLocator {
 public:
  /// Bounding boxes of the elements, for a cheap first test (once per mesh).
  explicit MeshLocator(const fem::Mesh& mesh);
  /// The first element that contains x (Newton on x(xi), inside with a tolerance of 1e-9 in
  /// local coordinates), or nullopt when x lies in none.
  std::optional<MeshLocation> locate(const fem::Vec3& x) const;
  /// sum_i N_i(xi) v_i of a nodal vector field stored as (v_x, v_y, v_z) per node.
  fem::Vec3 interpolate(const MeshLocation& at, const Eigen::VectorXd& nodal) const;

 private:
  const fem::Mesh& mesh_;
  std::vector<std::pair<fem::Vec3, fem::Vec3>> boxes_;
};

}  // namespace partita::adapters
