#include "partita/coupling/mapping/area_balanced_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "point_tree.hpp"

namespace partita::coupling {

std::shared_ptr<const config::Spec> AreaBalancedMapper::spec() {
  auto s = std::make_shared<config::Spec>(
      "area-balanced",
      "consistent and integral-preserving mapping of densities between weighted point sets (cell "
      "centres <-> quadrature points)");
  s->string("type", "the mapper's name, when the mapper is given as a map");
  s->integer("neighbors", "source points averaged by each target point").min(1).max(64).def(6);
  return s;
}

std::unique_ptr<Mapper> AreaBalancedMapper::create(const MapperContext& context) {
  const config::Node o = mapper_options(context.config, spec());
  const int k = o.is_map() ? static_cast<int>(o.integer("neighbors")) : 6;
  return std::make_unique<AreaBalancedMapper>(context.constraint, k);
}

SparseMapper::Matrix AreaBalancedMapper::interpolation(const Mesh& source,
                                                       const Mesh& target) const {
  for (const Mesh* m : {&source, &target})
    if (!m->has_weights())
      throw Error(
          "mapper 'area-balanced' needs point weights (the area each point stands for) on both "
          "meshes, and mesh '" +
          m->name() +
          "' has none; it maps between cell-centre and "
          "quadrature-point meshes (e.g. a DEM mesh's <name>_centres and an FE interface's "
          "<name>_quadrature); use nearest-projection or rbf for other meshes");
  const Eigen::Index ns = source.size(), nt = target.size();
  const Eigen::VectorXd& a = source.weights();
  const Eigen::VectorXd& w = target.weights();
  if (a.sum() <= 0 || w.sum() <= 0)
    throw Error("mapper 'area-balanced': the point weights of mesh '" +
                (a.sum() <= 0 ? source.name() : target.name()) + "' sum to zero");

  // Sparsity pattern: the k nearest source points of each target point, plus the nearest
  // target point of each source point. Initial weights exp(-(d / h)^2), h = sqrt(A_i).
  std::vector<Eigen::Triplet<double>> entries;
  const PointTree stree(source.points());
  std::vector<std::uint32_t> idx;
  std::vector<double> d2;
  const std::size_t k = static_cast<std::size_t>(std::min<Eigen::Index>(neighbors_, ns));
  auto kernel = [&](Eigen::Index i, double dist2) {
    const double h2 = std::max(a(i), 1e-300);
    return std::exp(-dist2 / h2) + 1e-12;
  };
  for (Eigen::Index q = 0; q < nt; ++q) {
    stree.nearest(target.points().row(q).transpose(), k, idx, d2);
    for (std::size_t j = 0; j < idx.size(); ++j)
      entries.emplace_back(q, static_cast<Eigen::Index>(idx[j]),
                           kernel(static_cast<Eigen::Index>(idx[j]), d2[j]));
  }
  const PointTree ttree(target.points());
  for (Eigen::Index i = 0; i < ns; ++i) {
    const auto [q, dist2] = ttree.nearest(source.points().row(i).transpose());
    entries.emplace_back(q, i, kernel(i, dist2));
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor> m(nt, ns);
  m.setFromTriplets(entries.begin(), entries.end(),
                    [](double x, double) { return x; });  // duplicates: keep one
  m.makeCompressed();

  // Sinkhorn balancing: columns to c_i = A_i sum(w)/sum(A), then rows to 1, repeated.
  const Eigen::VectorXd c = a * (w.sum() / a.sum());
  Eigen::VectorXd row(nt), col(ns);
  double worst = 0;
  for (int it = 0; it < 2000; ++it) {
    // column sums weighted by the target weights: sum_q w_q W_qi
    col.setZero();
    for (Eigen::Index i = 0; i < ns; ++i)
      for (Eigen::SparseMatrix<double>::InnerIterator e(m, i); e; ++e)
        col(i) += w(e.row()) * e.value();
    worst = 0;
    for (Eigen::Index i = 0; i < ns; ++i) {
      if (col(i) <= 0) continue;
      worst = std::max(worst, std::abs(col(i) - c(i)) / std::max(c(i), 1e-300));
      for (Eigen::SparseMatrix<double>::InnerIterator e(m, i); e; ++e)
        e.valueRef() *= c(i) / col(i);
    }
    row.setZero();
    for (Eigen::Index i = 0; i < ns; ++i)
      for (Eigen::SparseMatrix<double>::InnerIterator e(m, i); e; ++e) row(e.row()) += e.value();
    for (Eigen::Index i = 0; i < ns; ++i)
      for (Eigen::SparseMatrix<double>::InnerIterator e(m, i); e; ++e) e.valueRef() /= row(e.row());
    if (worst < 1e-13) break;
  }
  // After the last row scaling the rows sum to 1 exactly; the columns hold to `worst`.
  if (worst > 1e-8)
    log::get("coupling")
        ->warn(
            "mapper 'area-balanced' from '{}' to '{}': the integral is preserved only to {:.2e} "
            "(relative, per source point) after 2000 balancing sweeps; are the two meshes "
            "covering the same surface?",
            source.name(), target.name(), worst);
  return Matrix(m);
}

}  // namespace partita::coupling
