// The box filler: porosity, overlap bound, determinism, errors.

#include "partita/dem/packing_generator.hpp"
#include "partita/dem/error.hpp"

#include <catch2/catch.hpp>

#include <chrono>

using namespace partita::dem;

namespace {

PackingSpec seed_spec(double box) {
  PackingSpec spec;  // the seed 000 granules: 4.0, 3.125, 2.5 mm, 50 % porosity
  spec.hi = Eigen::Vector3d(box, box, box);
  spec.diameters = {4.0e-3, 3.125e-3, 2.5e-3};
  spec.fractions = {1.0, 1.0, 1.0};
  spec.porosity = 0.5;
  spec.seed = 1;
  return spec;
}

double max_overlap(const Packing& p) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < p.radii.size(); ++i)
    for (Eigen::Index j = i + 1; j < p.radii.size(); ++j)
      worst = std::max(worst,
                       p.radii[i] + p.radii[j] - (p.positions.row(i) - p.positions.row(j)).norm());
  return worst;
}

}  // namespace

TEST_CASE("dem: packing generator reaches the porosity with bounded overlaps", "[dem][generator]") {
  const PackingSpec spec = seed_spec(0.03);
  const auto t0 = std::chrono::steady_clock::now();
  const Packing p = PackingGenerator::generate(spec);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double r_min = 1.25e-3;
  INFO(p.radii.size() << " spheres, porosity " << p.porosity << ", max overlap "
                      << max_overlap(p) / r_min << " R_min, " << p.sweeps << " sweeps, " << seconds
                      << " s");
  CHECK(p.porosity == Approx(0.5).margin(0.005));
  CHECK(max_overlap(p) <= 0.01 * r_min);
  // inside the box
  for (Eigen::Index i = 0; i < p.radii.size(); ++i) {
    CHECK(p.positions.row(i).minCoeff() >= p.radii[i] * (1 - 1e-12));
    CHECK(p.positions.row(i).maxCoeff() <= 0.03 - p.radii[i] * (1 - 1e-12));
  }
  // equal numbers of the three sizes
  int n4 = 0;
  for (Eigen::Index i = 0; i < p.radii.size(); ++i) n4 += p.radii[i] == 2.0e-3;
  CHECK(3 * n4 == Approx(p.radii.size()).margin(3));
}

TEST_CASE("dem: packing generator is deterministic from the seed", "[dem][generator]") {
  PackingSpec spec = seed_spec(0.02);
  const Packing a = PackingGenerator::generate(spec);
  const Packing b = PackingGenerator::generate(spec);
  CHECK(a.positions == b.positions);
  CHECK(a.radii == b.radii);
  spec.seed = 2;
  const Packing c = PackingGenerator::generate(spec);
  CHECK(c.positions != a.positions);
}

TEST_CASE("dem: packing generator by mass fraction", "[dem][generator]") {
  PackingSpec spec = seed_spec(0.012);
  spec.diameters = {2.0e-3, 1.0e-3};
  spec.fractions = {0.5, 0.5};  // equal mass: 8 times more small spheres
  spec.basis = PackingSpec::Basis::mass;
  const Packing p = PackingGenerator::generate(spec);
  int small = 0;
  for (Eigen::Index i = 0; i < p.radii.size(); ++i) small += p.radii[i] == 0.5e-3;
  const int large = static_cast<int>(p.radii.size()) - small;
  CHECK(small == Approx(8 * large).margin(8));
  CHECK(p.porosity == Approx(0.5).margin(0.005));
}

TEST_CASE("dem: packing generator rejects bad input", "[dem][generator][errors]") {
  PackingSpec spec = seed_spec(0.02);
  spec.fractions = {1.0};
  CHECK_THROWS_AS(PackingGenerator::generate(spec), Error);
  spec = seed_spec(0.02);
  spec.porosity = 0.1;
  CHECK_THROWS_AS(PackingGenerator::generate(spec), Error);
  spec = seed_spec(0.003);  // 4 mm spheres in a 3 mm box
  CHECK_THROWS_WITH(PackingGenerator::generate(spec), Catch::Contains("does not fit"));
}
