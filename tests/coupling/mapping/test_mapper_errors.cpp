// User errors of the mappers: what the case file says wrong, and fields of the wrong size.
#include <catch2/catch.hpp>

#include "make_mapper.hpp"
#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"
#include "partita/coupling/mapping/rbf_mapper.hpp"
#include "plate_meshes.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;
using Catch::Matchers::Contains;

TEST_CASE("every mapper is registered with its options", "[mapping]") {
  const auto& r = mapper_registry();
  for (const char* name : {"nearest-neighbor", "nearest-projection", "rbf"})
    CHECK(r.contains(name));
  for (const auto& e : r.entries()) {
    CAPTURE(e.name);
    REQUIRE(e.spec);
    CHECK(!e.doc.empty());
    CHECK(e.spec->find("type") != nullptr);
  }
  CHECK_THAT(r.get("rbf").spec->docs(),
             Contains("support_radius") && Contains("polynomial") && Contains("basis"));
  CHECK_THAT(r.get("nearest-projection").spec->docs(), Contains("point_cloud"));
}

TEST_CASE("mappers are chosen by name, as a plain name or a map", "[mapping]") {
  CHECK(make_mapper("nearest-neighbor", Constraint::consistent)->name() == "nearest-neighbor");
  CHECK(make_mapper("{type: nearest-projection}", Constraint::conservative)->constraint() ==
        Constraint::conservative);
  auto rbf =
      make_mapper("{type: rbf, support_radius: 2 mm, polynomial: on}", Constraint::consistent);
  CHECK(rbf->name() == "rbf");
}

TEST_CASE("an unknown mapper name lists the known ones and the nearest", "[mapping]") {
  CHECK_THROWS_WITH(make_mapper("nearest-projektion", Constraint::consistent),
                    Contains("unknown mapper 'nearest-projektion'") &&
                        Contains("did you mean 'nearest-projection'") && Contains("rbf") &&
                        Contains("case.yaml:1"));
  CHECK_THROWS_WITH(make_mapper("{type: rbff, support_radius: 1.0e-3}", Constraint::consistent),
                    Contains("did you mean 'rbf'"));
  CHECK_THROWS_WITH(make_mapper("{support_radius: 1.0e-3}", Constraint::consistent),
                    Contains("needs 'type"));
  CHECK_THROWS_WITH(make_mapper("[rbf]", Constraint::consistent),
                    Contains("expected a mapper name"));
  CHECK_THROWS_AS(
      make_mapper("{type: nearest-neighbor, support_radius: 1.0e-3}", Constraint::consistent),
      partita::Error);  // an option that mapper does not have
}

TEST_CASE("rbf needs a positive support radius", "[mapping]") {
  CHECK_THROWS_WITH(make_mapper("rbf", Constraint::consistent),
                    Contains("support_radius") && Contains("{type: rbf"));
  CHECK_THROWS_WITH(make_mapper("{type: rbf}", Constraint::consistent),
                    Contains("support_radius") && Contains("case.yaml:1"));
  CHECK_THROWS_WITH(make_mapper("{type: rbf, support_radius: -2.0e-3}", Constraint::consistent),
                    Contains("support_radius") && Contains("-0.002") && Contains("0 < value"));
  CHECK_THROWS_AS(make_mapper("{type: rbf, support_radius: 0}", Constraint::consistent),
                  partita::Error);
  CHECK_THROWS_WITH(RbfMapper(Constraint::consistent, RbfMapper::Basis::wendland_c2, -1.0),
                    Contains("positive"));
  // thin-plate-spline takes no radius
  CHECK_NOTHROW(
      make_mapper("{type: rbf, basis: thin-plate-spline, polynomial: on}", Constraint::consistent));
  CHECK_THROWS_WITH(
      make_mapper("{type: rbf, support_radius: 1.0e-3, polynomial: off}", Constraint::conservative),
      Contains("total") && Contains("polynomial: separate"));
}

TEST_CASE("mapping a field with the wrong number of rows", "[mapping]") {
  const Mesh stl = plate_triangles("plate", 4, 4, 0.0, 1);
  const Mesh centres = cell_centres("plate_centres", stl);
  const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 3, 3, 0.0, 2);
  for (const char* yaml :
       {"nearest-neighbor", "nearest-projection", "{type: rbf, support_radius: 10 mm}"}) {
    CAPTURE(yaml);
    auto m = make_mapper(yaml, Constraint::consistent);
    Eigen::MatrixXd out;
    CHECK_THROWS_WITH(m->map(Eigen::MatrixXd::Zero(32, 3), out), Contains("before compute"));
    m->compute(centres, fe.quadrature);
    CHECK_THROWS_WITH(m->map(Eigen::MatrixXd::Zero(31, 3), out),
                      Contains("31 rows") && Contains("mesh 'plate_centres' has 32 points") &&
                          Contains("'bottom_quadrature'"));
    CHECK_NOTHROW(m->map(Eigen::MatrixXd::Zero(32, 3), out));
    CHECK(out.rows() == 36);
  }
}

TEST_CASE("nearest-projection onto a point cloud when told to refuse", "[mapping]") {
  const Mesh centres = cell_centres("plate_centres", plate_triangles("plate", 4, 4, 0.0, 1));
  const QuadFaces fe = plate_quads("bottom", "bottom_quadrature", 3, 3, 0.0, 2);
  auto m = make_mapper("{type: nearest-projection, point_cloud: error}", Constraint::consistent);
  CHECK_THROWS_WITH(m->compute(centres, fe.quadrature),
                    Contains("'plate_centres' has no triangles") && Contains("rbf") &&
                        Contains("nearest-neighbor"));
  CHECK_THROWS_WITH(
      make_mapper("{type: nearest-projection, point_cloud: nerest}", Constraint::consistent),
      Contains("nearest"));
}

TEST_CASE("global rbf bases refuse large meshes", "[mapping]") {
  const Mesh big = plate_random_points("big", RbfMapper::max_dense_points + 1, 3);
  const Mesh small = plate_random_points("small", 10, 4);
  auto m =
      make_mapper("{type: rbf, basis: gaussian, support_radius: 1 mm}", Constraint::consistent);
  CHECK_THROWS_WITH(m->compute(big, small), Contains("wendland-c2") && Contains("'big'"));
}

// The balance audit's bound comes from the mapper (a virtual, no cast to a mapper type): an
// explicit operator W >= 0 gives u = W^T omega; RBF (no explicit nonnegative W) gives none.
TEST_CASE("mappers: the balance bound W^T omega, where W >= 0 exists", "[mapping]") {
  Mesh::Points a(3, 3), b(2, 3);
  a << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  b << 0.1, 0, 0, 1.9, 0, 0;
  const Mesh from("from", a), to("to", b);
  NearestNeighborMapper nn(Constraint::consistent);
  nn.compute(from, to);
  Eigen::VectorXd u;
  REQUIRE(nn.arrival_bound(Eigen::Vector2d(2.0, 5.0), u));
  // target 0 takes source 0, target 1 takes source 2: u = (2, 0, 5)
  CHECK(u.size() == 3);
  CHECK(u(0) == 2.0);
  CHECK(u(1) == 0.0);
  CHECK(u(2) == 5.0);
  const Mapper& generic = nn;  // through the base class, as the audit asks
  CHECK(generic.arrival_bound(Eigen::Vector2d(1.0, 1.0), u));
}
