#include "partita/coupling/mapping/nearest_projection_mapper.hpp"
#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Cholesky>

#include "local_frame.hpp"
#include "partita/geometry/closest_point.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "point_tree.hpp"

namespace partita::coupling {

std::shared_ptr<const config::Spec> NearestProjectionMapper::spec() {
  auto s = std::make_shared<config::Spec>(
      "nearest-projection",
      "Projection onto the source triangles, barycentric interpolation; second order");
  s->string("type", "the mapper's name, when the mapper is given as a map");
  s->choice("point_cloud", "what to do when the mesh to project onto has no triangles",
            {"linear-fit", "nearest", "error"})
      .def("linear-fit");
  s->integer("neighbors", "number of nearest points of a linear fit on a point cloud")
      .min(3)
      .def(8);
  return s;
}

std::unique_ptr<Mapper> NearestProjectionMapper::create(const MapperContext& context) {
  const config::Node o = mapper_options(context.config, spec());
  const std::string pc = o.string("point_cloud");
  const PointCloud mode = pc == "nearest"
                              ? PointCloud::nearest
                              : (pc == "error" ? PointCloud::error : PointCloud::linear_fit);
  return std::make_unique<NearestProjectionMapper>(context.constraint, mode,
                                                   static_cast<int>(o.integer("neighbors")));
}

SparseMapper::Matrix NearestProjectionMapper::interpolation(const Mesh& source,
                                                            const Mesh& target) const {
  if (source.has_triangles()) return project(source, target);
  switch (point_cloud_) {
    case PointCloud::error:
      throw Error("mapper 'nearest-projection': mesh '" + source.name() +
                  "' has no triangles to project onto (a point cloud); use mapper 'rbf' or "
                  "'nearest-neighbor', or set point_cloud: linear-fit");
    case PointCloud::nearest: {
      log::get("coupling")
          ->debug("nearest-projection: mesh '{}' has no triangles; nearest point", source.name());
      return NearestNeighborMapper::weights(source, target);
    }
    case PointCloud::linear_fit:
      break;
  }
  log::get("coupling")
      ->debug("nearest-projection: mesh '{}' has no triangles; local linear fit", source.name());
  return linear_fit(source, target);
}

SparseMapper::Matrix NearestProjectionMapper::project(const Mesh& source,
                                                      const Mesh& target) const {
  const Mesh::Points& x = source.points();
  const Mesh::Triangles& tri = source.triangles();
  const Mesh::Points centroids = source.triangle_centroids();
  // r_max = max over triangles of the centroid-to-vertex distance; degenerate (zero-area)
  // triangles are skipped: they carry no surface
  double r_max = 0.0;
  std::vector<char> usable(static_cast<std::size_t>(tri.rows()), 0);
  for (Eigen::Index t = 0; t < tri.rows(); ++t) {
    const Eigen::Vector3d a = x.row(tri(t, 0)), b = x.row(tri(t, 1)), c = x.row(tri(t, 2));
    const double h2 =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if ((b - a).cross(c - a).squaredNorm() <= 1e-24 * h2 * h2) continue;
    usable[static_cast<std::size_t>(t)] = 1;
    for (int k = 0; k < 3; ++k)
      r_max = std::max(r_max, (x.row(tri(t, k)) - centroids.row(t)).norm());
  }
  const PointTree tree(centroids);
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(static_cast<std::size_t>(3 * target.size()));
  std::vector<std::pair<std::uint32_t, double>> candidates;
  for (Eigen::Index i = 0; i < target.size(); ++i) {
    const Eigen::Vector3d p = target.points().row(i).transpose();
    // The closest triangle T (distance d) has its centroid within d + r_max of p, and d is at
    // most the distance to the nearest centroid: search that radius.
    const double radius = std::sqrt(tree.nearest(p).second) + r_max;
    tree.within(p, radius * (1.0 + 1e-12) + 1e-300, candidates);
    double best = std::numeric_limits<double>::infinity();
    Eigen::Index best_t = -1;
    Eigen::Vector3d best_l = Eigen::Vector3d::Zero();
    for (const auto& [t32, unused] : candidates) {
      const Eigen::Index t = static_cast<Eigen::Index>(t32);
      if (!usable[static_cast<std::size_t>(t)]) continue;
      const Eigen::Vector3d a = x.row(tri(t, 0)), b = x.row(tri(t, 1)), c = x.row(tri(t, 2));
      const geometry::TriangleClosestPoint q = geometry::closest_point_on_triangle(p, a, b, c);
      const Eigen::Vector3d l(q.barycentric[0], q.barycentric[1], q.barycentric[2]);
      const double d2 = (l(0) * a + l(1) * b + l(2) * c - p).squaredNorm();
      if (d2 < best || (d2 == best && t < best_t)) {
        best = d2;
        best_t = t;
        best_l = l;
      }
    }
    if (best_t < 0)
      throw Error("mapper 'nearest-projection': mesh '" + source.name() +
                  "' has only degenerate (zero-area) triangles near point " + std::to_string(i) +
                  " of mesh '" + target.name() + "'");
    // value(p) = sum_k l_k value(v_k): barycentric interpolation on the closest triangle
    for (int k = 0; k < 3; ++k)
      if (best_l(k) != 0.0) w.emplace_back(i, tri(best_t, k), best_l(k));
  }
  Matrix m(target.size(), source.size());
  m.setFromTriplets(w.begin(), w.end());
  return m;
}

SparseMapper::Matrix NearestProjectionMapper::linear_fit(const Mesh& source,
                                                         const Mesh& target) const {
  const Mesh::Points& x = source.points();
  const PointTree tree(x);
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(neighbors_),
                                              static_cast<std::size_t>(x.rows()));
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(static_cast<std::size_t>(target.size()) * k);
  std::vector<std::uint32_t> index;
  std::vector<double> dist2;
  Eigen::MatrixXd a;
  Eigen::VectorXd omega;
  for (Eigen::Index i = 0; i < target.size(); ++i) {
    const Eigen::Vector3d p = target.points().row(i).transpose();
    tree.nearest(p, k, index, dist2);
    const std::size_t n = index.size();
    // the principal directions of the neighbours (a plane on a surface); out-of-plane
    // scatter below 5 % of the in-plane extent is curvature, not a direction to fit
    LocalFrame frame = local_frame(x, index, 0.05);
    frame.origin = p;  // coordinates relative to p: the fitted value at p is the constant term
    int d = frame.dims();
    while (d > 0 && static_cast<std::size_t>(d) + 1 > n) --d;
    // Weighted least squares, basis A_j = [1, xi_1(x_j) .. xi_d(x_j)], weights
    // D_j = (1 - (r_j / R)^2)^2 with R = 1.5 r_k:
    //   value(p) = e_0^T (A^T D A)^{-1} A^T D f  =>  omega_j = D_j A_j z,  (A^T D A) z = e_0,
    // so sum_j omega_j = 1 and linear fields (in the frame) are reproduced exactly.
    const double r2 = 2.25 * dist2.back() + 1e-300;
    Eigen::VectorXd dw(static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) {
      const double s = 1.0 - dist2[j] / r2;
      dw(static_cast<Eigen::Index>(j)) = s * s;
    }
    for (;; --d) {
      a.resize(static_cast<Eigen::Index>(n), d + 1);
      for (std::size_t j = 0; j < n; ++j) {
        a(static_cast<Eigen::Index>(j), 0) = 1.0;
        if (d > 0)
          a.row(static_cast<Eigen::Index>(j)).tail(d) =
              frame.coordinates(x.row(index[j]).transpose()).head(d).transpose();
      }
      const Eigen::MatrixXd m = a.transpose() * dw.asDiagonal() * a;
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
      const Eigen::VectorXd dd = ldlt.vectorD().cwiseAbs();
      if (d == 0 || (ldlt.info() == Eigen::Success && dd.minCoeff() > 1e-10 * dd.maxCoeff())) {
        const Eigen::VectorXd z = ldlt.solve(Eigen::VectorXd::Unit(d + 1, 0));
        omega = dw.cwiseProduct(a * z);
        break;
      }
    }
    for (std::size_t j = 0; j < n; ++j)
      if (omega(static_cast<Eigen::Index>(j)) != 0.0)
        w.emplace_back(i, index[j], omega(static_cast<Eigen::Index>(j)));
  }
  Matrix m(target.size(), source.size());
  m.setFromTriplets(w.begin(), w.end());
  return m;
}

}  // namespace partita::coupling
