#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"

#include <vector>

#include "point_tree.hpp"

namespace partita::coupling {

std::shared_ptr<const config::Spec> NearestNeighborMapper::spec() {
  auto s = std::make_shared<config::Spec>(
      "nearest-neighbor",
      "Value of the nearest source point (k-d tree); first order, any point sets");
  s->string("type", "the mapper's name, when the mapper is given as a map");
  return s;
}

std::unique_ptr<Mapper> NearestNeighborMapper::create(const MapperContext& context) {
  mapper_options(context.config, spec());
  return std::make_unique<NearestNeighborMapper>(context.constraint);
}

SparseMapper::Matrix NearestNeighborMapper::interpolation(const Mesh& source,
                                                          const Mesh& target) const {
  return weights(source, target);
}

SparseMapper::Matrix NearestNeighborMapper::weights(const Mesh& source, const Mesh& target) {
  const PointTree tree(source.points());
  const Eigen::Index n = target.size();
  // W_ij = 1 if j is the source point nearest to target point i, else 0
  Matrix w(n, source.size());
  w.reserve(Eigen::VectorXi::Constant(n, 1));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d q = target.points().row(i).transpose();
    w.insert(i, tree.nearest(q).first) = 1.0;
  }
  return w;
}

}  // namespace partita::coupling
