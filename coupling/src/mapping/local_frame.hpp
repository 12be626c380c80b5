#pragma once
// The principal directions of a point set that have extent (for polynomial terms and local
// linear fits on planar or line-like point sets): the eigenvectors of the covariance whose
// standard deviation exceeds `relative_tolerance` times the largest one.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace partita::coupling {

struct LocalFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3Xd axes = Eigen::Matrix3Xd(3, 0);  ///< 3 x d, orthonormal, scaled by 1/scale
  double scale = 1.0;                              ///< largest standard deviation [m]
  int dims() const { return static_cast<int>(axes.cols()); }
  /// Scaled coordinates (xi_1 .. xi_d) of x in the frame.
  Eigen::VectorXd coordinates(const Eigen::Vector3d& x) const {
    return axes.transpose() * (x - origin);
  }
};

/// The frame of the points x_i (rows of `points` selected by `index`, or all when empty).
template <class Points, class Indices>
LocalFrame local_frame(const Points& points, const Indices& index, double relative_tolerance) {
  LocalFrame f;
  const Eigen::Index n = static_cast<Eigen::Index>(index.size());
  auto row = [&](Eigen::Index k) -> Eigen::Vector3d {
    return points.row(static_cast<Eigen::Index>(index[static_cast<std::size_t>(k)])).transpose();
  };
  if (n == 0) return f;
  for (Eigen::Index k = 0; k < n; ++k) f.origin += row(k);
  f.origin /= static_cast<double>(n);
  // C = 1/n sum (x_i - m)(x_i - m)^T
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::Vector3d d = row(k) - f.origin;
    cov.noalias() += d * d.transpose();
  }
  cov /= static_cast<double>(n);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d sd = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // ascending
  f.scale = sd(2) > 0.0 ? sd(2) : 1.0;
  int d = 0;
  for (int k = 2; k >= 0; --k)
    if (sd(k) > relative_tolerance * sd(2) && sd(2) > 0.0) ++d;
  f.axes.resize(3, d);
  for (int k = 0; k < d; ++k) f.axes.col(k) = eig.eigenvectors().col(2 - k) / f.scale;
  return f;
}

}  // namespace partita::coupling
