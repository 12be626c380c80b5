#include "partita/interface/mesh.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "partita/interface/error.hpp"

namespace partita {

Mesh::Mesh(std::string name, Points points, Triangles triangles)
    : name_(std::move(name)), points_(std::move(points)), triangles_(std::move(triangles)) {
  check();
}

void Mesh::check() const {
  if (!points_.allFinite())
    throw Error("mesh '" + name_ + "': a point coordinate is NaN or infinite");
  const Eigen::Index n = points_.rows();
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (triangles_(t, k) < 0 || triangles_(t, k) >= n)
        throw Error("mesh '" + name_ + "': triangle " + std::to_string(t) + " refers to point " +
                    std::to_string(triangles_(t, k)) + ", but the mesh has " + std::to_string(n) +
                    " points (allowed: 0.." + std::to_string(n - 1) + ")");
}

void Mesh::set_points(Points points) {
  if (points.rows() != points_.rows())
    throw Error("mesh '" + name_ + "': set_points() got " + std::to_string(points.rows()) +
                " points, the mesh has " + std::to_string(points_.rows()));
  points_ = std::move(points);
  check();
}

void Mesh::set_weights(Eigen::VectorXd weights) {
  if (weights.size() != points_.rows())
    throw Error("mesh '" + name_ + "': " + std::to_string(weights.size()) + " weights for " +
                std::to_string(points_.rows()) + " points");
  if (!weights.allFinite() || (weights.size() > 0 && weights.minCoeff() < 0))
    throw Error("mesh '" + name_ + "': point weights must be finite and >= 0");
  weights_ = std::move(weights);
}

Eigen::VectorXd Mesh::triangle_areas() const {
  Eigen::VectorXd a(triangles_.rows());
  // A = |(x1 - x0) x (x2 - x0)| / 2
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
    const Eigen::Vector3d x0 = points_.row(triangles_(t, 0));
    const Eigen::Vector3d e1 = Eigen::Vector3d(points_.row(triangles_(t, 1))) - x0;
    const Eigen::Vector3d e2 = Eigen::Vector3d(points_.row(triangles_(t, 2))) - x0;
    a(t) = 0.5 * e1.cross(e2).norm();
  }
  return a;
}

Mesh::Points Mesh::triangle_normals() const {
  Points n(triangles_.rows(), 3);
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t) {
    const Eigen::Vector3d x0 = points_.row(triangles_(t, 0));
    const Eigen::Vector3d e1 = Eigen::Vector3d(points_.row(triangles_(t, 1))) - x0;
    const Eigen::Vector3d e2 = Eigen::Vector3d(points_.row(triangles_(t, 2))) - x0;
    const Eigen::Vector3d c = e1.cross(e2);
    const double len = c.norm();
    n.row(t) = len > 0 ? Eigen::Vector3d(c / len) : Eigen::Vector3d::Zero();
  }
  return n;
}

Mesh::Points Mesh::triangle_centroids() const {
  Points c(triangles_.rows(), 3);
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t)
    c.row(t) = (points_.row(triangles_(t, 0)) + points_.row(triangles_(t, 1)) +
                points_.row(triangles_(t, 2))) /
               3.0;
  return c;
}

double Mesh::total_area() const {
  return triangle_areas().sum();
}

Mesh::Box Mesh::bounding_box() const {
  Box b;
  if (points_.rows() == 0) return b;
  b.min = points_.colwise().minCoeff().transpose();
  b.max = points_.colwise().maxCoeff().transpose();
  return b;
}

}  // namespace partita
