// nearest-projection is second order on a smooth field on a curved surface: a cylinder patch
// triangulated at four resolutions, the field known analytically, target points on the exact
// cylinder. Projection onto the chords moves a point by O(h^2) and linear interpolation errs
// by O(h^2): the max error falls like h^2.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "make_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

namespace {

constexpr double radius = 0.01, angle = EIGEN_PI / 2.0, height = 0.02;

// f(theta, z) = sin(2 theta) cos(pi z / H) (+ a second column)
Eigen::VectorXd field(const Eigen::Vector3d& x) {
  const double th = std::atan2(x.y(), x.x());
  return Eigen::Vector2d(std::sin(2.0 * th) * std::cos(EIGEN_PI * x.z() / height),
                         std::cos(th) + x.z() / height);
}

/// Least-squares slope of log(e) against log(h).
double fitted_order(const std::vector<double>& h, const std::vector<double>& e) {
  const double n = static_cast<double>(h.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double x = std::log(h[i]), y = std::log(e[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

TEST_CASE("nearest-projection converges with order 2 on a cylinder patch", "[mapping]") {
  // 3000 target points on the exact cylinder, strictly inside the patch
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.02, 0.98);
  Mesh::Points p(3000, 3);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const double th = angle * u(rng);
    p.row(i) << radius * std::cos(th), radius * std::sin(th), height * u(rng);
  }
  const Mesh target("probe", p);
  const Eigen::MatrixXd exact = sample(p, 2, field);
  std::vector<double> hs, errors;
  for (int n : {6, 12, 24, 48}) {
    const Mesh source = cylinder_patch("cylinder", radius, angle, height, n, n);
    auto m = make_mapper("nearest-projection", Constraint::consistent);
    m->compute(source, target);
    Eigen::MatrixXd out;
    m->map(sample(source.points(), 2, field), out);
    hs.push_back(radius * angle / n);
    errors.push_back((out - exact).cwiseAbs().maxCoeff());
  }
  const double order = fitted_order(hs, errors);
  CAPTURE(errors[0], errors[1], errors[2], errors[3], order);
  WARN("nearest-projection on a cylinder: max errors " << errors[0] << ", " << errors[1] << ", "
                                                       << errors[2] << ", " << errors[3]
                                                       << "; fitted order " << order);
  CHECK(order == Approx(2.0).margin(0.3));
}

TEST_CASE("nearest-projection's linear fit on a point cloud converges with order 2 on the plate",
          "[mapping]") {
  // Cell centres of the perturbed plate triangulation as the source (no triangles).
  auto f = [](const Eigen::Vector3d& x) {
    return Eigen::VectorXd::Constant(
        1, std::sin(EIGEN_PI * x.x() / plate_size) * std::cos(EIGEN_PI * x.y() / plate_size));
  };
  const Mesh target = plate_random_points("probe", 3000, 32);
  const Eigen::MatrixXd exact = sample(target.points(), 1, f);
  std::vector<double> hs, errors;
  for (int n : {8, 16, 32, 64}) {
    const Mesh centres = cell_centres("plate_centres", plate_triangles("plate", n, n, 0.3, 33));
    auto m = make_mapper("nearest-projection", Constraint::consistent);
    m->compute(centres, target);
    Eigen::MatrixXd out;
    m->map(sample(centres.points(), 1, f), out);
    hs.push_back(plate_size / n);
    errors.push_back((out - exact).cwiseAbs().maxCoeff());
  }
  const double order = fitted_order(hs, errors);
  WARN("linear fit on the cell centres: max errors " << errors[0] << ", " << errors[1] << ", "
                                                     << errors[2] << ", " << errors[3]
                                                     << "; fitted order " << order);
  CHECK(order == Approx(2.0).margin(0.3));
}
