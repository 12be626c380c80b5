#pragma once
// Test meshes for the mappers: the 20 mm x 20 mm plate of the seed case as an STL-like
// triangulation and as quad faces with their 2x2 Gauss points, both with randomly perturbed
// interior nodes (so they never match), and a cylinder patch (a curved surface).

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "partita/interface/mesh.hpp"

namespace partita::coupling::test {

inline constexpr double plate_size = 0.02;  // [m]
inline constexpr double plate_z = 0.02;     // the plate's bottom face [m]

/// (nx+1) x (ny+1) grid nodes of the plate; interior nodes moved in-plane by up to
/// `perturb` x spacing (uniform, seeded).
inline Mesh::Points plate_grid(int nx, int ny, double perturb, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double hx = plate_size / nx, hy = plate_size / ny;
  Mesh::Points p((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      double x = i * hx, y = j * hy;
      const double dx = u(rng), dy = u(rng);
      if (i > 0 && i < nx) x += perturb * hx * dx;
      if (j > 0 && j < ny) y += perturb * hy * dy;
      p.row(j * (nx + 1) + i) << x, y, plate_z;
    }
  return p;
}

/// STL-like triangulation of the plate: every grid cell split in two, diagonals alternating.
inline Mesh plate_triangles(const std::string& name, int nx, int ny, double perturb,
                            unsigned seed) {
  Mesh::Triangles t(2 * nx * ny, 3);
  int k = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 2, d = a + nx + 1;
      if ((i + j) % 2 == 0) {
        t.row(k++) << a, b, c;
        t.row(k++) << a, c, d;
      } else {
        t.row(k++) << a, b, d;
        t.row(k++) << b, c, d;
      }
    }
  return Mesh(name, plate_grid(nx, ny, perturb, seed), t);
}

/// The cell-centre mesh of a triangulation: points = centroids, no triangles.
inline Mesh cell_centres(const std::string& name, const Mesh& surface) {
  return Mesh(name, surface.triangle_centroids());
}

/// Quad faces (bilinear, perturbed grid) of the plate and their 2x2 Gauss points.
struct QuadFaces {
  Mesh nodes;               ///< the face nodes, each quad split into two triangles
  Mesh quadrature;          ///< the Gauss points (no triangles)
  Eigen::VectorXd weights;  ///< w_q = det J(xi_q) (Gauss weights are 1) [m^2]
};

inline QuadFaces plate_quads(const std::string& nodes_name, const std::string& qp_name, int nx,
                             int ny, double perturb, unsigned seed) {
  const Mesh::Points x = plate_grid(nx, ny, perturb, seed);
  Mesh::Triangles t(2 * nx * ny, 3);
  Mesh::Points qp(4 * nx * ny, 3);
  Eigen::VectorXd w(4 * nx * ny);
  const double g = 1.0 / std::sqrt(3.0);
  int k = 0, q = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int n[4] = {j * (nx + 1) + i, j * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i + 1,
                        (j + 1) * (nx + 1) + i};
      t.row(k++) << n[0], n[1], n[2];
      t.row(k++) << n[0], n[2], n[3];
      for (double eta : {-g, g})
        for (double xi : {-g, g}) {
          // x(xi, eta) = sum_a N_a x_a, N_a = (1 + xi xi_a)(1 + eta eta_a)/4
          const double xa[4] = {-1, 1, 1, -1}, ea[4] = {-1, -1, 1, 1};
          Eigen::Vector3d pos = Eigen::Vector3d::Zero();
          Eigen::Matrix2d jac = Eigen::Matrix2d::Zero();
          for (int a = 0; a < 4; ++a) {
            const Eigen::Vector3d xn = x.row(n[a]).transpose();
            pos += 0.25 * (1 + xi * xa[a]) * (1 + eta * ea[a]) * xn;
            const double dxi = 0.25 * xa[a] * (1 + eta * ea[a]),
                         deta = 0.25 * ea[a] * (1 + xi * xa[a]);
            jac(0, 0) += dxi * xn.x();
            jac(0, 1) += deta * xn.x();
            jac(1, 0) += dxi * xn.y();
            jac(1, 1) += deta * xn.y();
          }
          qp.row(q) = pos.transpose();
          w(q++) = jac.determinant();
        }
    }
  return QuadFaces{Mesh(nodes_name, x, t), Mesh(qp_name, qp), w};
}

/// Uniform random points on the plate.
inline Mesh plate_random_points(const std::string& name, Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, plate_size);
  Mesh::Points p(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) p.row(i) << u(rng), u(rng), plate_z;
  return Mesh(name, p);
}

/// f at every point of a mesh (rows), C columns.
inline Eigen::MatrixXd sample(const Mesh::Points& x, int columns,
                              const std::function<Eigen::VectorXd(const Eigen::Vector3d&)>& f) {
  Eigen::MatrixXd v(x.rows(), columns);
  for (Eigen::Index i = 0; i < x.rows(); ++i) v.row(i) = f(x.row(i).transpose()).transpose();
  return v;
}

/// Integral of f over each triangle (7-point Dunavant rule, degree 5), rows = triangles.
inline Eigen::MatrixXd triangle_integrals(
    const Mesh& m, int columns, const std::function<Eigen::VectorXd(const Eigen::Vector3d&)>& f) {
  struct P {
    double w, l0, l1, l2;
  };
  const double a1 = 0.059715871789770, b1 = 0.470142064105115, w1 = 0.132394152788506;
  const double a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827;
  const P rule[7] = {{0.225, 1.0 / 3, 1.0 / 3, 1.0 / 3},
                     {w1, a1, b1, b1},
                     {w1, b1, a1, b1},
                     {w1, b1, b1, a1},
                     {w2, a2, b2, b2},
                     {w2, b2, a2, b2},
                     {w2, b2, b2, a2}};
  const Eigen::VectorXd area = m.triangle_areas();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(m.num_triangles(), columns);
  for (Eigen::Index t = 0; t < m.num_triangles(); ++t) {
    const Eigen::Vector3d a = m.points().row(m.triangles()(t, 0)),
                          b = m.points().row(m.triangles()(t, 1)),
                          c = m.points().row(m.triangles()(t, 2));
    for (const P& p : rule)
      out.row(t) += area(t) * p.w * f(p.l0 * a + p.l1 * b + p.l2 * c).transpose();
  }
  return out;
}

/// A cylinder patch of radius r, angle 0..theta, height 0..h: n_theta x n_z cells, two
/// triangles each, vertices on the cylinder.
inline Mesh cylinder_patch(const std::string& name, double r, double theta, double h, int n_theta,
                           int n_z) {
  Mesh::Points p((n_theta + 1) * (n_z + 1), 3);
  for (int j = 0; j <= n_z; ++j)
    for (int i = 0; i <= n_theta; ++i) {
      const double a = theta * i / n_theta;
      p.row(j * (n_theta + 1) + i) << r * std::cos(a), r * std::sin(a), h * j / n_z;
    }
  Mesh::Triangles t(2 * n_theta * n_z, 3);
  int k = 0;
  for (int j = 0; j < n_z; ++j)
    for (int i = 0; i < n_theta; ++i) {
      const int a = j * (n_theta + 1) + i, b = a + 1, c = a + n_theta + 2, d = a + n_theta + 1;
      t.row(k++) << a, b, c;
      t.row(k++) << a, c, d;
    }
  return Mesh(name, p, t);
}

}  // namespace partita::coupling::test
