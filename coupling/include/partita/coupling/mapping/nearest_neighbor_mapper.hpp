#pragma once
// nearest-neighbor: each target point takes the value of the nearest source point (consistent);
// each source value goes whole to the nearest target point (conservative). First order; the
// search is a k-d tree over the source points, O(n log n). A source point given more than once
// (within 1e-9 of the source's extent: the centres of the two sides of a face between two
// elements, each side a triangle of its own) is handed out in index order to the target points
// that find it: meshes that list the same points in the same order map point k to point k.

#include <memory>

#include "partita/coupling/mapping/sparse_mapper.hpp"

namespace partita::coupling {

class NearestNeighborMapper final : public SparseMapper {
 public:
  explicit NearestNeighborMapper(Constraint constraint) : SparseMapper(constraint) {}

  std::string name() const override { return "nearest-neighbor"; }

  /// Its options (only `type`).
  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Mapper> create(const MapperContext& context);

  /// W_ij = 1 if source point j is the nearest to target point i (target x source).
  static Matrix weights(const Mesh& source, const Mesh& target);

 protected:
  Matrix interpolation(const Mesh& source, const Mesh& target) const override;
};

}  // namespace partita::coupling
