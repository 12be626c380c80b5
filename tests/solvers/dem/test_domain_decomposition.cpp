// Recursive coordinate bisection of a bed into subdomains: the boxes tile the bed's box, every
// point has exactly one owner (the box that holds it), the counts are balanced for any number of
// subdomains, the cuts do not depend on the particles' order, and near() finds exactly the boxes
// within a distance (against a brute-force search).

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using partita::dem::DomainDecomposition;
using partita::dem::Error;
using Eigen::Vector3d;

namespace {

// A bed that is not uniform: a dense heap in one corner and a sparse layer over the floor.
std::vector<Vector3d> uneven_bed(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vector3d> x;
  x.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 4 != 0)
      x.emplace_back(0.3 * u(rng), 0.2 * u(rng), 0.25 * u(rng));  // the heap
    else
      x.emplace_back(2.0 * u(rng), 1.0 * u(rng), 0.05 * u(rng));  // the layer
  }
  return x;
}

bool inside(const DomainDecomposition::Box& b, const Vector3d& x) {
  for (int d = 0; d < 3; ++d)
    if (!(x[d] >= b.lo[d] && x[d] < b.hi[d])) return false;
  return true;
}

}  // namespace

TEST_CASE("dem: domain decomposition: the boxes tile the bed and balance the particles",
          "[dem][decomposition]") {
  const Vector3d lo(0, 0, 0), hi(2.0, 1.0, 0.5);
  const std::vector<Vector3d> bed = uneven_bed(10007, 3);
  for (int parts : {1, 2, 3, 4, 5, 7, 8, 16}) {
    INFO(parts << " subdomains");
    const DomainDecomposition d = DomainDecomposition::bisection(bed, lo, hi, parts);
    REQUIRE(d.parts() == parts);
    // the volumes add up to the box's and no two boxes overlap
    double volume = 0.0;
    for (int p = 0; p < parts; ++p) {
      const auto& b = d.box(p);
      CHECK((b.hi - b.lo).minCoeff() > 0.0);
      volume += (b.hi - b.lo).prod();
      for (int q = p + 1; q < parts; ++q) {
        const auto& c = d.box(q);
        const Vector3d overlap = b.hi.cwiseMin(c.hi) - b.lo.cwiseMax(c.lo);
        CHECK(overlap.minCoeff() <= 0.0);
      }
    }
    CHECK(volume == Approx((hi - lo).prod()).epsilon(1e-12));
    // each particle's owner is the one box that holds it; the counts are those the cuts aim at:
    // n parts / parts within one particle per cut level (distinct coordinates)
    std::vector<std::size_t> count(static_cast<std::size_t>(parts), 0);
    for (const Vector3d& x : bed) {
      const int o = d.owner(x);
      REQUIRE((o >= 0 && o < parts));
      CHECK(inside(d.box(o), x));
      int holding = 0;
      for (int p = 0; p < parts; ++p) holding += inside(d.box(p), x);
      CHECK(holding == 1);
      ++count[static_cast<std::size_t>(o)];
    }
    const auto [mn, mx] = std::minmax_element(count.begin(), count.end());
    const double ideal = static_cast<double>(bed.size()) / parts;
    CHECK(static_cast<double>(*mn) >= std::floor(ideal) - 4);
    CHECK(static_cast<double>(*mx) <= std::ceil(ideal) + 4);
  }
}

TEST_CASE("dem: domain decomposition: the cuts do not depend on the particles' order",
          "[dem][decomposition]") {
  std::vector<Vector3d> bed = uneven_bed(5000, 11);
  const Vector3d lo(0, 0, 0), hi(2.0, 1.0, 0.5);
  const DomainDecomposition a = DomainDecomposition::bisection(bed, lo, hi, 6);
  std::mt19937_64 rng(1);
  std::shuffle(bed.begin(), bed.end(), rng);
  const DomainDecomposition b = DomainDecomposition::bisection(bed, lo, hi, 6);
  for (int p = 0; p < 6; ++p) {
    CHECK(a.box(p).lo == b.box(p).lo);
    CHECK(a.box(p).hi == b.box(p).hi);
  }
}

TEST_CASE("dem: domain decomposition: near() finds every other box within the distance",
          "[dem][decomposition]") {
  const Vector3d lo(0, 0, 0), hi(2.0, 1.0, 0.5);
  const DomainDecomposition d = DomainDecomposition::bisection(uneven_bed(4000, 5), lo, hi, 7);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  std::vector<int> got, expected;
  std::size_t ghosts = 0;
  for (int k = 0; k < 2000; ++k) {
    // points in the box and a little outside it (particles that left since the cuts)
    const Vector3d x(2.0 * u(rng), u(rng), 0.5 * u(rng));
    const double r = 0.12 * (k % 5) / 4.0;  // 0 ... 0.12
    d.near(x, r, got);
    const int o = d.owner(x);
    expected.clear();
    for (int p = 0; p < d.parts(); ++p) {
      const auto& b = d.box(p);
      const double dist = (x.cwiseMax(b.lo).cwiseMin(b.hi) - x).norm();
      if (p != o && dist <= r) expected.push_back(p);
    }
    CHECK(got == expected);
    ghosts += got.size();
    // outside the bed, the owner is the box that holds the point moved onto the bed's box
    const Vector3d onto = x.cwiseMax(lo).cwiseMin(hi - Vector3d::Constant(1e-12));
    CHECK(d.owner(x) == d.owner(onto));
  }
  CHECK(ghosts > 100);  // the search was exercised
}

TEST_CASE("dem: domain decomposition: a heap of equal coordinates and bad input",
          "[dem][decomposition]") {
  // every particle at one point: one box gets them all, the others none, each box non-empty
  const std::vector<Vector3d> same(100, Vector3d(0.5, 0.5, 0.5));
  const DomainDecomposition d =
      DomainDecomposition::bisection(same, Vector3d::Zero(), Vector3d::Ones(), 4);
  int owners = 0;
  for (int p = 0; p < 4; ++p) owners += d.owner(same[0]) == p;
  CHECK(owners == 1);
  // no particles: cuts in proportion to the subdomains (equal volumes for a power of two)
  const DomainDecomposition e = DomainDecomposition::bisection({}, Vector3d::Zero(), Vector3d::Ones(), 4);
  for (int p = 0; p < 4; ++p) CHECK((e.box(p).hi - e.box(p).lo).prod() == Approx(0.25));
  CHECK(DomainDecomposition().owner(Vector3d(7, 8, 9)) == 0);

  CHECK_THROWS_AS(DomainDecomposition::bisection(same, Vector3d::Zero(), Vector3d::Ones(), 0), Error);
  CHECK_THROWS_AS(DomainDecomposition::bisection(same, Vector3d::Ones(), Vector3d::Zero(), 2), Error);
  std::vector<Vector3d> nan = same;
  nan[7].y() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(DomainDecomposition::bisection(nan, Vector3d::Zero(), Vector3d::Ones(), 2),
                    Catch::Contains("position 7"));
  std::vector<int> out;
  CHECK_THROWS_AS(d.near(Vector3d::Zero(), -1.0, out), Error);
}
