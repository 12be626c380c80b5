#pragma once
// A coupling mesh: a named set of points with optional triangles, in the reference configuration.
// Data lives on points; a participant with data at cell centres exposes a second mesh whose
// points are the centres.

#include <string>

#include <Eigen/Core>

namespace partita {

class Mesh {
 public:
  using Points = Eigen::MatrixX3d;                          ///< N x 3 coordinates [m]
  using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3>;  ///< M x 3 point indices

  struct Box {
    Eigen::Vector3d min = Eigen::Vector3d::Zero();
    Eigen::Vector3d max = Eigen::Vector3d::Zero();
    Eigen::Vector3d size() const { return max - min; }
    double diagonal() const { return (max - min).norm(); }
  };

  Mesh() = default;
  /// Throws partita::Error if a triangle index is out of range or a coordinate is not finite.
  Mesh(std::string name, Points points, Triangles triangles = Triangles(0, 3));

  const std::string& name() const { return name_; }
  void set_name(std::string name) { name_ = std::move(name); }
  const Points& points() const { return points_; }
  const Triangles& triangles() const { return triangles_; }
  Eigen::Index size() const { return points_.rows(); }
  Eigen::Index num_triangles() const { return triangles_.rows(); }
  bool has_triangles() const { return triangles_.rows() > 0; }

  /// Replace the coordinates (same number of points), e.g. after a mesh moved.
  void set_points(Points points);

  /// Optional point weights: the area [m^2] each point stands for (a cell-centre mesh: the cell
  /// areas; a quadrature-point mesh: the quadrature weights). Empty when not given. Mappers that
  /// preserve integrals of densities use them. Throws on a wrong length or a negative weight.
  void set_weights(Eigen::VectorXd weights);
  const Eigen::VectorXd& weights() const { return weights_; }
  bool has_weights() const { return weights_.size() > 0; }

  /// Area of each triangle [m^2] (M).
  Eigen::VectorXd triangle_areas() const;
  /// Unit normal of each triangle, right-hand rule on (v0, v1, v2) (M x 3).
  Points triangle_normals() const;
  /// Centroid of each triangle (M x 3).
  Points triangle_centroids() const;
  /// Sum of the triangle areas [m^2].
  double total_area() const;
  /// Axis-aligned bounding box of the points.
  Box bounding_box() const;

 private:
  void check() const;

  std::string name_;
  Points points_ = Points(0, 3);
  Triangles triangles_ = Triangles(0, 3);
  Eigen::VectorXd weights_;
};

}  // namespace partita
