// The route of the seed case (000, Fig. 1 and Algorithm 1): contact forces f_c at the STL cell
// centres -> tractions t_c = f_c / A_c (the writing participant's job) -> interpolated to the
// surface quadrature points of the other participant's face. Mesh names as the adapters use
// them: `plate_centres` (points = STL triangle centroids, no triangles) and `bottom_quadrature`
// (points = Gauss points, no triangles). The integral of the mapped traction over the face,
// sum_q t_q w_q, must give back the total force sum_c f_c up to the discretisation error.
#include <catch2/catch.hpp>

#include <cmath>

#include "make_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

namespace {

// A smooth traction on the plate [Pa]: shear and a non-uniform pressure,
//   t(x, y) = p0 (0.1 s, -0.05 s, -(1 + 0.5 s)),  s = sin(pi x / L) cos(2 pi y / L)
constexpr double p0 = 10.0e3;
Eigen::VectorXd traction(const Eigen::Vector3d& x) {
  const double s =
      std::sin(EIGEN_PI * x.x() / plate_size) * std::cos(2.0 * EIGEN_PI * x.y() / plate_size);
  return p0 * Eigen::Vector3d(0.1 * s, -0.05 * s, -(1.0 + 0.5 * s));
}
// Bound on the second derivatives: |D^2 t_k| <= p0 0.5 (a^2 + b^2), a = pi/L, b = 2 pi/L
// (the largest amplitude of s among the components is 0.5 p0).
const double m2 =
    p0 * 0.5 * (std::pow(EIGEN_PI / plate_size, 2) + std::pow(2.0 * EIGEN_PI / plate_size, 2));
const double m1 = p0 * 0.5 * std::hypot(EIGEN_PI / plate_size, 2.0 * EIGEN_PI / plate_size);

struct Route {
  double error;   // max over components |sum_q t_q w_q - sum_c f_c| [N]
  double total;   // |sum_c f_c| of the normal component [N]
  double h_cell;  // largest STL edge [m]
  double h_face;  // largest face-node spacing [m]
};

double longest_edge(const Mesh& m) {
  double h = 0.0;
  for (Eigen::Index t = 0; t < m.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k)
      h = std::max(
          h, (m.points().row(m.triangles()(t, k)) - m.points().row(m.triangles()(t, (k + 1) % 3)))
                 .norm());
  return h;
}

Route run_route(const std::string& mapper, int n_cells, int n_quads,
                const Eigen::RowVector3d& uniform = {0, 0, 0}) {
  const Mesh stl = plate_triangles("plate", n_cells, n_cells, 0.3, 21);
  const Mesh plate_centres = cell_centres("plate_centres", stl);
  const QuadFaces face = plate_quads("bottom", "bottom_quadrature", n_quads, n_quads, 0.3, 22);
  // The writing side: exact cell resultants f_c = int_cell t dA, tractions t_c = f_c / A_c.
  Eigen::MatrixXd f = triangle_integrals(stl, 3, traction);
  if (uniform.norm() > 0) f = stl.triangle_areas() * uniform;
  const Eigen::MatrixXd t_c = f.array().colwise() / stl.triangle_areas().array();
  // The coupling core: traction is intensive -> consistent.
  auto m = make_mapper(mapper, Constraint::consistent);
  m->compute(plate_centres, face.quadrature);
  Eigen::MatrixXd t_q;
  m->map(t_c, t_q);
  // The reading side: F = sum_q t_q w_q.
  const Eigen::RowVector3d integral = face.weights.transpose() * t_q;
  const Eigen::RowVector3d total = f.colwise().sum();
  return Route{(integral - total).cwiseAbs().maxCoeff(), std::abs(total(2)), longest_edge(stl),
               longest_edge(face.nodes)};
}

}  // namespace

TEST_CASE("seed route: a uniform traction arrives exactly", "[mapping]") {
  // Constant tractions are reproduced exactly and sum_q w_q = area = sum_c A_c: roundoff only.
  const Eigen::RowVector3d t(200.0, -100.0, -10.0e3);
  for (const char* mapper :
       {"nearest-projection", "nearest-neighbor", "{type: rbf, support_radius: 3 mm}"}) {
    CAPTURE(mapper);
    const Route r = run_route(mapper, 20, 12, t);
    CHECK(r.error <= 1e-12 * 10.0e3 * plate_size * plate_size);
  }
}

TEST_CASE("seed route: the integral of the mapped traction equals the total force", "[mapping]") {
  // Error sources, each bounded by the second derivatives (|D^2 t| <= M2) on the plate area A:
  //   t_c (cell mean) vs t(centroid): <= M2 h_c^2 / 2;  the linear fit / barycentric /
  //   polynomial interpolation at a Gauss point: <= M2 (1.5 h_c)^2 / 2 times the sum of |weights|
  //   (about 1.3 for the fit); the 2x2 Gauss rule on the face: <= M2 h_f^2 / 2.
  // Bound asserted: |sum_q t_q w_q - sum_c f_c| <= A M2 (2 h_c^2 + h_f^2).
  // (nearest-neighbor is first order: A M1 h_c.)
  const double area = plate_size * plate_size;
  for (const char* mapper :
       {"nearest-projection", "{type: rbf, support_radius: 3 mm}", "nearest-neighbor"}) {
    CAPTURE(mapper);
    const Route coarse = run_route(mapper, 16, 10);
    const Route fine = run_route(mapper, 32, 20);
    const bool first_order = std::string(mapper) == "nearest-neighbor";
    for (const Route& r : {coarse, fine}) {
      const double bound = first_order
                               ? area * m1 * r.h_cell
                               : area * m2 * (2.0 * r.h_cell * r.h_cell + r.h_face * r.h_face);
      CAPTURE(r.error, bound, r.total, r.h_cell, r.h_face);
      CHECK(r.error <= bound);
      CHECK(r.error <= 0.01 * r.total);  // and under 1 % of the total force
    }
    // second order: halving h cuts the error by about 4 (at least 3 asserted)
    if (!first_order) CHECK(fine.error < coarse.error / 3.0);
    auto ratio = [&](const Route& r) {
      return r.error / (first_order
                            ? area * m1 * r.h_cell
                            : area * m2 * (2.0 * r.h_cell * r.h_cell + r.h_face * r.h_face));
    };
    WARN(mapper << ": |sum t_q w_q - sum f_c| / |F_z| = " << coarse.error / coarse.total
                << " (16/10 cells), " << fine.error / fine.total
                << " (32/20 cells); error / bound = " << ratio(coarse) << ", " << ratio(fine));
  }
}
