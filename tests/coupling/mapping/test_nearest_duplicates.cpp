// nearest-neighbor between point sets that hold a point more than once (the centres of the two
// sides of a face between two elements: each side a triangle of its own, at the same place):
// two meshes that list the same points in the same order map point k to point k, in both
// directions (consistent and conservative), whatever the k-d tree would find first.
#include <catch2/catch.hpp>

#include "make_mapper.hpp"
#include "partita/interface/mesh.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

TEST_CASE("nearest-neighbor: a point given twice maps to itself in order", "[mapping]") {
  // 40 distinct places on a warped grid, each given 1, 2 or 3 times, the copies apart in the list
  // (and one copy off by a rounding error, as a centroid summed in another vertex order is)
  std::vector<Eigen::RowVector3d> places;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 5; ++j)
      places.emplace_back(0.01 * i, 0.013 * j + 0.001 * i * i, 0.002 * std::sin(i + j));
  std::vector<int> place_of;
  for (std::size_t p = 0; p < places.size(); ++p) place_of.push_back(static_cast<int>(p));
  for (std::size_t p = 0; p < places.size(); p += 2) place_of.push_back(static_cast<int>(p));
  for (std::size_t p = 0; p < places.size(); p += 5) place_of.push_back(static_cast<int>(p));
  Mesh::Points x(static_cast<Eigen::Index>(place_of.size()), 3);
  for (std::size_t k = 0; k < place_of.size(); ++k) {
    x.row(static_cast<Eigen::Index>(k)) = places[static_cast<std::size_t>(place_of[k])];
    if (k % 7 == 3) x(static_cast<Eigen::Index>(k), 0) *= 1.0 + 1e-15;
  }
  const Mesh source("sides", x), target("sides_centres", x);
  Eigen::MatrixXd values(x.rows(), 1);
  for (Eigen::Index k = 0; k < x.rows(); ++k) values(k, 0) = static_cast<double>(k);
  for (const Constraint c : {Constraint::consistent, Constraint::conservative}) {
    auto m = make_mapper("nearest-neighbor", c);
    m->compute(source, target);
    Eigen::MatrixXd out;
    m->map(values, out);
    REQUIRE(out.rows() == x.rows());
    CHECK((out - values).cwiseAbs().maxCoeff() == 0.0);
  }
  // a target point between two distinct sources keeps the nearest one
  Mesh::Points y(1, 3);
  y.row(0) = places[0] + 0.3 * (places[1] - places[0]);
  auto m = make_mapper("nearest-neighbor", Constraint::consistent);
  m->compute(source, Mesh("probe", y));
  Eigen::MatrixXd out;
  m->map(values, out);
  CHECK(place_of[static_cast<std::size_t>(out(0, 0))] == 0);
}
