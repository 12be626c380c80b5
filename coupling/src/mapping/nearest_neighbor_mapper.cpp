#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <utility>
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
  // Source points closer to each other than `same` are one point given more than once (the
  // centres of the two sides of a face between two elements); the target points at such a
  // place take them one after the other, in index order, so that two meshes that list the same
  // points in the same order map point k to point k.
  double same = 0.0;
  if (source.size() > 0) {
    const Eigen::Vector3d extent =
        source.points().colwise().maxCoeff() - source.points().colwise().minCoeff();
    same = 1e-9 * std::max(extent.norm(), 1e-300);
  }
  std::vector<std::pair<std::uint32_t, double>> found;
  std::vector<std::uint32_t> group;
  std::unordered_map<std::uint32_t, std::size_t> taken;  // first index of a group -> targets so far
  // W_ij = 1 if j is the source point nearest to target point i, else 0
  Matrix w(n, source.size());
  w.reserve(Eigen::VectorXi::Constant(n, 1));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d q = target.points().row(i).transpose();
    Eigen::Index j = tree.nearest(q).first;
    tree.within(source.points().row(j).transpose(), same, found);
    if (found.size() > 1) {
      group.clear();
      for (const auto& f : found) group.push_back(f.first);
      std::sort(group.begin(), group.end());
      const std::size_t k = taken[group.front()]++;
      j = static_cast<Eigen::Index>(group[k % group.size()]);
    }
    w.insert(i, j) = 1.0;
  }
  return w;
}

}  // namespace partita::coupling
