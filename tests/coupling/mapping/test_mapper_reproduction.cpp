// Consistent mappers reproduce constant fields exactly (rows of W sum to 1), and
// nearest-projection and rbf with its polynomial reproduce linear fields on a plane exactly
// (barycentric interpolation / the polynomial part hold linear functions).
#include <catch2/catch.hpp>

#include <cstring>

#include <Eigen/Geometry>

#include "make_mapper.hpp"
#include "partita/coupling/mapping/rbf_mapper.hpp"
#include "partita/coupling/mapping/sparse_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

namespace {

const char* const consistent_mappers[] = {
    "nearest-neighbor",
    "nearest-projection",
    "{type: nearest-projection, point_cloud: nearest}",
    "{type: rbf, support_radius: 3.5 mm}",
    "{type: rbf, support_radius: 3.5e-3, polynomial: on}",
    "{type: rbf, support_radius: 3.5e-3, polynomial: off}",
    "{type: rbf, support_radius: 3.5e-3, solver: cg}",
    "{type: rbf, basis: gaussian, support_radius: 1.5e-3}",
    "{type: rbf, basis: thin-plate-spline, polynomial: on}",
};

// Mappers that hold linear fields: nearest-projection (on triangles, and the linear fit on a
// point cloud) and rbf with the polynomial.
const char* const linear_mappers[] = {
    "nearest-projection",
    "{type: rbf, support_radius: 3.5e-3}",
    "{type: rbf, support_radius: 3.5e-3, polynomial: on}",
    "{type: rbf, support_radius: 3.5e-3, polynomial: on, solver: cg, tolerance: 1.0e-13}",
    "{type: rbf, support_radius: 3.5e-3, solver: cg}",
    "{type: rbf, basis: gaussian, support_radius: 1.5e-3}",
    "{type: rbf, basis: thin-plate-spline, polynomial: on}",
};

Mesh rotated(const Mesh& m, const Eigen::Matrix3d& r) {
  return Mesh(m.name(), m.points() * r.transpose(), m.triangles());
}

}  // namespace

TEST_CASE("consistent mappers reproduce a constant field exactly", "[mapping]") {
  // STL-like plate (17 x 17 cells, 578 triangles) to Gauss points of 13 x 13 quads, both perturbed.
  const Mesh stl = plate_triangles("plate", 17, 17, 0.3, 1);
  const Mesh centres = cell_centres("plate_centres", stl);
  const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 13, 13, 0.3, 2);
  const Eigen::RowVector3d c(1.5, -2.0, 3.0e4);
  for (const char* yaml : consistent_mappers) {
    for (const Mesh* source : {&stl, &centres}) {
      CAPTURE(yaml, source->name());
      auto m = make_mapper(yaml, Constraint::consistent);
      if (std::string(yaml).find("polynomial: off") != std::string::npos)
        continue;  // no constants: see below
      m->compute(*source, fe.quadrature);
      Eigen::MatrixXd out;
      m->map(Eigen::MatrixXd(c.replicate(source->size(), 1)), out);
      REQUIRE(out.rows() == fe.quadrature.size());
      REQUIRE(out.cols() == 3);
      // out_i = sum_j W_ij c = c, W_ij summing to 1: roundoff only
      const double err = (out.rowwise() - c).cwiseAbs().maxCoeff();
      CHECK(err <= 1e-12 * c.cwiseAbs().maxCoeff());
    }
  }
}

TEST_CASE("rbf without polynomial does not hold constants (so conservative use is refused)",
          "[mapping]") {
  const Mesh stl = plate_triangles("plate", 17, 17, 0.3, 1);
  const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 13, 13, 0.3, 2);
  auto m =
      make_mapper("{type: rbf, support_radius: 3.5e-3, polynomial: off}", Constraint::consistent);
  m->compute(stl, fe.quadrature);
  Eigen::MatrixXd out;
  m->map(Eigen::MatrixXd::Ones(stl.size(), 1), out);
  // The Wendland interpolant of 1 dips between centres by a few per cent, but is close to 1.
  CHECK((out.array() - 1.0).abs().maxCoeff() > 1e-6);
  CHECK((out.array() - 1.0).abs().maxCoeff() < 0.2);
}

TEST_CASE("nearest-projection and rbf with polynomial reproduce a linear field on a plane",
          "[mapping]") {
  // The plane z = 0.02 as given, and the same meshes rotated by 35 degrees about (1, 1, 0.3):
  // then x, y and z all vary but the points stay coplanar, and the polynomial must drop its
  // term normal to the plane (the principal direction without extent).
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(35.0 * EIGEN_PI / 180.0, Eigen::Vector3d(1, 1, 0.3).normalized())
          .toRotationMatrix();
  for (bool tilt : {false, true}) {
    const Eigen::Matrix3d r = tilt ? rot : Eigen::Matrix3d::Identity();
    const Mesh stl = rotated(plate_triangles("plate", 17, 17, 0.3, 1), r);
    const Mesh centres = cell_centres("plate_centres", stl);
    const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 13, 13, 0.3, 2);
    const Mesh target = rotated(fe.quadrature, r);
    auto f = [](const Eigen::Vector3d& x) {
      // f(x) = (1 + 300 x - 200 y + 100 z, 5 - 400 x + 50 z) (a linear field, two components)
      return Eigen::Vector2d(1.0 + 300.0 * x.x() - 200.0 * x.y() + 100.0 * x.z(),
                             5.0 - 400.0 * x.x() + 50.0 * x.z());
    };
    const Eigen::MatrixXd expected = sample(target.points(), 2, f);
    for (const char* yaml : linear_mappers)
      for (const Mesh* source : {&stl, &centres}) {
        CAPTURE(tilt, yaml, source->name());
        auto m = make_mapper(yaml, Constraint::consistent);
        m->compute(*source, target);
        Eigen::MatrixXd out;
        m->map(sample(source->points(), 2, f), out);
        CHECK((out - expected).cwiseAbs().maxCoeff() <= 1e-10 * expected.cwiseAbs().maxCoeff());
        if (auto* rbf = dynamic_cast<RbfMapper*>(m.get())) CHECK(rbf->polynomial_terms() == 3);
      }
  }
}

TEST_CASE("recompute after the target mesh moved", "[mapping]") {
  const Mesh stl = plate_triangles("plate", 10, 10, 0.3, 4);
  Mesh target = plate_random_points("probe", 200, 5);
  auto m = make_mapper("nearest-projection", Constraint::consistent);
  auto f = [](const Eigen::Vector3d& x) {
    return Eigen::VectorXd::Constant(1, 2.0 + 100.0 * x.x() + 30.0 * x.y());
  };
  const Eigen::MatrixXd in = sample(stl.points(), 1, f);
  m->compute(stl, target);
  // move the probe points in-plane (shrink towards the centre) and compute again
  Mesh::Points moved = target.points();
  moved.leftCols(2) = (moved.leftCols(2).array() - 0.01) * 0.5 + 0.01;
  target.set_points(moved);
  m->compute(stl, target);
  Eigen::MatrixXd out;
  m->map(in, out);
  CHECK((out - sample(moved, 1, f)).cwiseAbs().maxCoeff() <= 1e-12 * 4.0);
}

TEST_CASE("rbf: conjugate gradients give the Cholesky solution to their tolerance", "[mapping]") {
  const Mesh stl = plate_triangles("plate", 30, 30, 0.3, 7);
  const Mesh target = plate_random_points("probe", 500, 8);
  auto f = [](const Eigen::Vector3d& x) {
    return Eigen::VectorXd::Constant(1, std::sin(300.0 * x.x()) * std::cos(200.0 * x.y()));
  };
  const Eigen::MatrixXd in = sample(stl.points(), 1, f);
  Eigen::MatrixXd direct, iterative;
  auto a = make_mapper("{type: rbf, support_radius: 2.5e-3}", Constraint::consistent);
  auto b = make_mapper("{type: rbf, support_radius: 2.5e-3, solver: cg, tolerance: 1.0e-12}",
                       Constraint::consistent);
  a->compute(stl, target);
  b->compute(stl, target);
  a->map(in, direct);
  b->map(in, iterative);
  // ||x - x*|| <= cond(Phi) tol ||x*||; the values are O(1)
  CHECK((direct - iterative).cwiseAbs().maxCoeff() < 1e-8);
}

TEST_CASE("a sparse mapper's map() gives the sparse product W in bit for bit", "[mapping]") {
  // Each row of W in: ((0 + w_1 x_1) + w_2 x_2) + ... in the stored order, every operation
  // IEEE-rounded: Eigen's own sparse product, and map() whatever vector width it uses (3
  // components: x, y, z of a point in one register), must give the same bits.
  Mesh from = plate_triangles("from", 13, 11, 0.2, 1), to = plate_triangles("to", 8, 9, 0.2, 2);
  from.set_weights(Eigen::VectorXd::Constant(from.size(), 0.04 / double(from.size())));
  to.set_weights(Eigen::VectorXd::Constant(to.size(), 0.04 / double(to.size())));
  // Dense input, and sparse input (a few loaded points among zeros of both signs, as a face
  // that granules touch at a few cells).
  for (const char* name : {"nearest-neighbor", "nearest-projection", "area-balanced",
                           "{type: area-balanced, neighbors: 12}"})
    for (const Constraint c : {Constraint::consistent, Constraint::conservative})
      for (const int components : {1, 2, 3, 4})
        for (const int loaded : {-1, 0, 1, 7}) {  // -1: every point
          INFO(name << ", " << components << " components, loaded points " << loaded);
          auto m = make_mapper(name, c);
          m->compute(from, to);
          const auto* sparse = dynamic_cast<const SparseMapper*>(m.get());
          REQUIRE(sparse != nullptr);
          Eigen::MatrixXd in = Eigen::MatrixXd::Random(from.size(), components);
          if (loaded >= 0) {
            const Eigen::MatrixXd values = in;
            in.setZero();
            for (Eigen::Index j = 0; j < in.rows(); j += 2) in.row(j).setConstant(-0.0);
            for (int k = 0; k < loaded; ++k) in.row(11 * k + 4) = values.row(11 * k + 4);
          }
          in.row(3).setZero();
          in(5, 0) = -0.0;
          Eigen::MatrixXd out;
          for (int repeat = 0; repeat < 2; ++repeat) {  // the second call reuses the scratch
            m->map(in, out);
            const Eigen::MatrixXd expected = sparse->matrix() * in;
            REQUIRE(out.rows() == expected.rows());
            REQUIRE(out.cols() == expected.cols());
            CHECK(std::memcmp(out.data(), expected.data(),
                              sizeof(double) * static_cast<std::size_t>(out.size())) == 0);
          }
        }
}
