// area-balanced at large sizes (10^5 interface cells): the operator is built exactly,
// not iterated, so its two properties hold to round-off at any size. Independent reasons:
//   rows sum to 1 and W >= 0          (the contract: constants reproduced, convex weights);
//   sum_q w_q W_qi = A_i sum(w)/sum(A) (the integral preserved per source point; the reference
//                                      totals summed in long double, 1e-16 relative);
//   entries only between points at most 3 coarse spacings apart (both meshes cover the plate
//   uniformly, so the two bisection cuts of the same weight lie within about a spacing);
//   a linear field arrives within its gradient times that distance (convex weights).

#include <catch2/catch.hpp>

#include <cmath>

#include "partita/coupling/mapping/area_balanced_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

namespace {

struct Route {
  Mesh centres;     // STL cell centres, weights = triangle areas
  Mesh quadrature;  // FE Gauss points, weights = det J
  double spacing;   // the coarser of the two meshes' grid spacings
};

Route seed_route(int stl_cells_per_side, int fe_cells_per_side) {
  const Mesh stl = plate_triangles("plate", stl_cells_per_side, stl_cells_per_side, 0.3, 7);
  Mesh centres = cell_centres("plate_centres", stl);
  centres.set_weights(stl.triangle_areas());
  QuadFaces fe =
      plate_quads("bottom", "bottom_quadrature", fe_cells_per_side, fe_cells_per_side, 0.3, 8);
  fe.quadrature.set_weights(fe.weights);
  const double h = plate_size / std::min(stl_cells_per_side, fe_cells_per_side);
  return {std::move(centres), std::move(fe.quadrature), h};
}

long double accurate_sum(const Eigen::VectorXd& v) {
  long double s = 0.0L;
  for (const double x : v) s += x;
  return s;
}

void check_balance(const Route& r, int neighbors) {
  AreaBalancedMapper m(Constraint::consistent, neighbors);
  m.compute(r.centres, r.quadrature);
  const SparseMapper::Matrix& w = m.matrix();
  const Eigen::VectorXd& wq = r.quadrature.weights();
  const Eigen::VectorXd& a = r.centres.weights();

  // rows: sum_i W_qi = 1, every W_qi >= 0
  double row_err = 0.0, most_negative = 0.0, farthest = 0.0;
  for (Eigen::Index q = 0; q < w.outerSize(); ++q) {
    double row = 0.0;
    for (SparseMapper::Matrix::InnerIterator e(w, q); e; ++e) {
      row += e.value();
      most_negative = std::min(most_negative, e.value());
      farthest = std::max(farthest,
                          (r.quadrature.points().row(q) - r.centres.points().row(e.col())).norm());
    }
    row_err = std::max(row_err, std::abs(row - 1.0));
  }

  // columns: sum_q w_q W_qi = c_i = A_i sum(w) / sum(A)
  const Eigen::VectorXd c = a * static_cast<double>(accurate_sum(wq) / accurate_sum(a));
  const Eigen::VectorXd col = w.transpose() * wq;
  const double col_err = ((col - c).array() / c.array()).abs().maxCoeff();

  // a linear field (x in mm) arrives within its gradient times the reach of the weights
  Eigen::MatrixXd f = r.centres.points().col(0) * 1e3;
  Eigen::MatrixXd out;
  m.map(f, out);
  const double lin_err = (out.col(0) - r.quadrature.points().col(0) * 1e3).cwiseAbs().maxCoeff();
  INFO("neighbors " << neighbors << ": entries " << w.nonZeros() << ", row error " << row_err
                    << ", column error " << col_err << ", farthest " << farthest / r.spacing
                    << " spacings, linear-field error " << lin_err / (r.spacing * 1e3)
                    << " spacings");
  CHECK(row_err <= 1e-13);
  CHECK(most_negative == 0.0);
  CHECK(col_err <= 1e-12);
  CHECK(farthest <= 3.0 * r.spacing);
  CHECK(lin_err <= farthest * 1e3);
}

}  // namespace

TEST_CASE("area-balanced at 1e5 cells: rows and the integral per source point exact", "[mapping]") {
  // 2 x 224^2 = 100352 STL cells -> 4 x 166^2 = 110224 Gauss points (non-matching, perturbed)
  check_balance(seed_route(224, 166), 1);
}

TEST_CASE("area-balanced with smoothing over neighbours keeps both properties", "[mapping]") {
  check_balance(seed_route(70, 52), 6);  // 9800 cells -> 10816 Gauss points
}

TEST_CASE("area-balanced: a target point of zero weight still reproduces constants", "[mapping]") {
  Route r = seed_route(8, 6);
  Eigen::VectorXd w = r.quadrature.weights();
  w(5) = 0.0;
  r.quadrature.set_weights(w);
  AreaBalancedMapper m(Constraint::consistent);
  m.compute(r.centres, r.quadrature);
  const Eigen::MatrixXd one = Eigen::MatrixXd::Ones(r.centres.size(), 1);
  Eigen::MatrixXd out;
  m.map(one, out);
  CHECK((out.array() - 1.0).abs().maxCoeff() <= 1e-14);
}
