#pragma once
// nearest-projection: each target point is projected onto the closest source triangle and
// takes the barycentric interpolation of the triangle's vertex values; off the surface the
// closest point clamps to the nearest edge or vertex. Exact for linear fields on a plane,
// second order on smooth curved surfaces. The closest triangle is found exactly through a k-d
// tree over the triangle centroids: a radius search of |p - c_nearest| + r_max (r_max: the
// largest centroid-to-vertex distance), never a loop over all pairs.
//
// A source mesh without triangles (a point cloud, e.g. the cell-centre mesh of a participant
// that has its data at cell centres) has nothing to project onto. Option `point_cloud` decides:
//   linear-fit (default)  a weighted least-squares linear fit over the `neighbors` nearest source
//                         points, in their local principal plane (or line, or space): exact for
//                         linear fields, second order like the projection; weights sum to 1
//   nearest               the nearest source point (first order)
//   error                 refuse, naming the mesh (suggests rbf or nearest-neighbor)
// In a conservative mapping the same applies with the roles swapped (the target's triangles).

#include <memory>

#include "partita/coupling/mapping/sparse_mapper.hpp"

namespace partita::coupling {

class NearestProjectionMapper final : public SparseMapper {
 public:
  enum class PointCloud { linear_fit, nearest, error };

  NearestProjectionMapper(Constraint constraint, PointCloud point_cloud = PointCloud::linear_fit,
                          int neighbors = 8)
      : SparseMapper(constraint), point_cloud_(point_cloud), neighbors_(neighbors) {}

  std::string name() const override { return "nearest-projection"; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Mapper> create(const MapperContext& context);

 protected:
  Matrix interpolation(const Mesh& source, const Mesh& target) const override;

 private:
  Matrix project(const Mesh& source, const Mesh& target) const;
  Matrix linear_fit(const Mesh& source, const Mesh& target) const;

  PointCloud point_cloud_;
  int neighbors_;
};

}  // namespace partita::coupling
