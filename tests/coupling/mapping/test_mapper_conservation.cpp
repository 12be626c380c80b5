// Conservative mappers distribute an extensive quantity (force) with columns of W^T summing
// to 1, so the total arriving equals the total sent (roundoff only).
#include <catch2/catch.hpp>

#include <random>

#include "make_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

namespace {

const char* const conservative_mappers[] = {
    "nearest-neighbor",
    "nearest-projection",
    "{type: nearest-projection, point_cloud: nearest}",
    "{type: rbf, support_radius: 3.5e-3}",
    "{type: rbf, support_radius: 3.5e-3, polynomial: on}",
    "{type: rbf, support_radius: 3.5e-3, solver: cg}",
    "{type: rbf, basis: gaussian, support_radius: 1.5e-3}",
    "{type: rbf, basis: thin-plate-spline, polynomial: on}",
};

/// Forces at n points: a compressive mean plus noise, like contact forces (3 columns) [N].
Eigen::MatrixXd random_forces(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd f(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) f.row(i) << 0.2 * u(rng), 0.2 * u(rng), -1.0 + 0.8 * u(rng);
  return f;
}

}  // namespace

TEST_CASE("conservative mappers preserve the total force", "[mapping]") {
  // Forces at the cell centres of an STL-like plate (23 x 23 cells, 1058 points) go to the nodes
  // of quad faces (11 x 11, given with triangles, and as bare points), and back from the face
  // nodes to the STL vertices. Non-matching, both perturbed.
  const Mesh stl = plate_triangles("plate", 23, 23, 0.3, 11);
  const Mesh centres = cell_centres("plate_centres", stl);
  const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 11, 11, 0.3, 12);
  const Mesh fe_points("bottom_points", fe.nodes.points());
  struct Route {
    const Mesh* from;
    const Mesh* to;
  };
  const Route routes[] = {
      {&centres, &fe.nodes}, {&centres, &fe_points}, {&fe.nodes, &stl}, {&stl, &fe.quadrature}};
  double worst = 0.0;
  for (const char* yaml : conservative_mappers)
    for (const Route& r : routes) {
      CAPTURE(yaml, r.from->name(), r.to->name());
      auto m = make_mapper(yaml, Constraint::conservative);
      REQUIRE(m->constraint() == Constraint::conservative);
      m->compute(*r.from, *r.to);
      const Eigen::MatrixXd f = random_forces(r.from->size(), 13);
      Eigen::MatrixXd out;
      m->map(f, out);
      REQUIRE(out.rows() == r.to->size());
      // sum_i out_i = sum_i sum_j (W^T)_ij f_j = sum_j f_j, columns of W^T summing to 1;
      // measured against sum |f_j|, the scale of the roundoff
      const Eigen::RowVectorXd err = (out.colwise().sum() - f.colwise().sum()).cwiseAbs();
      const Eigen::RowVectorXd scale = f.cwiseAbs().colwise().sum();
      const double rel = (err.array() / scale.array()).maxCoeff();
      worst = std::max(worst, rel);
      CHECK(rel <= 1e-12);
    }
  WARN("worst relative conservation error " << worst);
}

TEST_CASE(
    "conservative nearest-projection distributes a force to the vertices of the triangle it hits",
    "[mapping]") {
  // One force at (0.3, 0.2) on the unit square split along its diagonal: the barycentric
  // weights of the lower triangle (0,0),(1,0),(1,1) are (0.7, 0.1, 0.2).
  Mesh::Points x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Mesh::Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  const Mesh square("square", x, t);
  Mesh::Points p(1, 3);
  p << 0.3, 0.2, 0.05;
  const Mesh point("force_point", p);
  auto m = make_mapper("nearest-projection", Constraint::conservative);
  m->compute(point, square);
  Eigen::MatrixXd out;
  m->map(Eigen::MatrixXd::Constant(1, 1, 10.0), out);
  CHECK(out(0, 0) == Approx(7.0).epsilon(1e-14));
  CHECK(out(1, 0) == Approx(1.0).epsilon(1e-14));
  CHECK(out(2, 0) == Approx(2.0).epsilon(1e-14));
  CHECK(out(3, 0) == 0.0);
}
