// The audits of a run over its exchanges: a run stops on non-finite values of an audited
// exchange (whose check reads the audit's totals), naming the exchange and the window; the
// balance audit measures |total received - total sent| against the larger of the two.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../array_solver.hpp"
#include "../ode_participant.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/case_run.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::run;
using test::ArraySolver;

TEST_CASE("a NaN in an audited exchange stops the run with the exchange and the window",
          "[coupling][exchange][divergence]") {
  // Forces (extensive: audited for their balance) turning NaN at t = 0.25: the run stops in the
  // window that produced them, naming the participant and the field.
  Registries r = test::test_registries();
  auto spec = std::make_shared<config::Spec>("test-array", "37 points writing and reading f");
  spec->real("nan_from", "time from which f has a NaN").def(1e300);
  r.solvers.add(
      "test-array", "array solver",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<ArraySolver>(37, DataKind::extensive, c.config.real("nan_from"));
      },
      spec);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("partita_exchange_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "nan.yaml";
  std::ofstream(file) << "case: nan\ntime: {window: 0.1, end: 1.0}\n"
                         "participants:\n"
                         "  one: {solver: test-array, nan_from: 0.25}\n"
                         "  two: {solver: test-array}\n"
                         "coupling:\n  scheme: explicit-serial\n  exchanges:\n"
                         "    - {data: f, from: one.points, to: two.points}\n";
  RunOptions o;
  o.output_dir = dir / "out";
  std::string what = "no error";
  try {
    CaseRun run(file, r, o);
    run.run();
  } catch (const Error& e) {
    what = e.what();
  }
  CHECK_THAT(what, Catch::Contains("window 3 ") && Catch::Contains("participant 'one' sent") &&
                       Catch::Contains("non-finite values (1 of 111)") &&
                       Catch::Contains("'f' on one.points"));
  std::filesystem::remove_all(dir);
}

namespace {

// Runs 10 windows of `one` (n1 points) sending f = (1, 1, 1) at every point to `two` (n2 points)
// through nearest-neighbor with `constraint`; returns the imbalance column of coupling.csv and
// the number of windows that warned.
struct AuditRun {
  std::vector<double> imbalance;
  long warnings = 0;
};
AuditRun audit_run(const std::string& kind, double w1, double w2, const std::string& constraint) {
  Registries r = test::test_registries();
  auto spec = std::make_shared<config::Spec>("test-points", "points writing and reading f");
  spec->integer("points", "number of points").min(1).def(37);
  spec->real("weight", "the weight of every point (0: none)").def(0.0);
  spec->string("kind", "extensive or intensive").def("extensive");
  r.solvers.add(
      "test-points", "array solver",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<ArraySolver>(
            c.config.integer("points"),
            c.config.string("kind") == "extensive" ? DataKind::extensive : DataKind::intensive,
            INFINITY, c.config.real("weight"));
      },
      spec);
  const auto dir =
      std::filesystem::temp_directory_path() / ("partita_audit_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "audit.yaml";
  std::ofstream(file) << "case: audit\ntime: {window: 0.1, end: 1.0}\n"
                         "participants:\n"
                         "  one: {solver: test-points, points: 37, kind: "
                      << kind << ", weight: " << w1
                      << "}\n  two: {solver: test-points, points: 23, kind: " << kind
                      << ", weight: " << w2 << "}\n"
                      << "coupling:\n  scheme: explicit-serial\n  exchanges:\n"
                         "    - {data: f, from: one.points, to: two.points, mapper: "
                         "nearest-neighbor, constraint: "
                      << constraint << "}\n";
  RunOptions o;
  o.output_dir = dir / "out";
  AuditRun result;
  {
    CaseRun run(file, r, o);
    run.run();
    result.warnings = run.summary().imbalance_warnings;
  }
  std::ifstream csv(dir / "out" / "coupling.csv");
  std::string line;
  std::getline(csv, line);
  const bool audited = line.find("imbalance 'f' one.points -> two.points") != std::string::npos;
  while (audited && std::getline(csv, line)) {
    std::stringstream row(line);
    std::string cell;
    for (int c = 0; c < 4; ++c) std::getline(row, cell, ',');  // window, time, iterations, it
    result.imbalance.push_back(std::stod(cell));
  }
  std::filesystem::remove_all(dir);
  return result;
}

}  // namespace

TEST_CASE("the balance audit measures |total received - total sent| / max(|sent|, |received|)",
          "[coupling][exchange][audit]") {
  // 37 points send (1, 1, 1) each; nearest-neighbor gives 23 points. Consistent: each target
  // takes one source's value, so 23 arrive of 37; conservative: each source's value goes to one
  // target, all 37 arrive. Magnitudes: sqrt(3) a point.
  SECTION("extensive data (sums)") {
    const AuditRun consistent = audit_run("extensive", 0.0, 0.0, "consistent");
    REQUIRE(consistent.imbalance.size() == 10);
    for (const double v : consistent.imbalance) CHECK(v == Approx(14.0 / 37.0).epsilon(1e-9));
    CHECK(consistent.warnings == 10);
    const AuditRun conservative = audit_run("extensive", 0.0, 0.0, "conservative");
    REQUIRE(conservative.imbalance.size() == 10);
    for (const double v : conservative.imbalance) CHECK(std::abs(v) < 1e-15);
    CHECK(conservative.warnings == 0);
  }
  SECTION("intensive data on weighted points (integrals)") {
    // sent: 37 x 0.5 = 18.5 a component; received (consistent): 23 x 2 = 46
    const AuditRun consistent = audit_run("intensive", 0.5, 2.0, "consistent");
    REQUIRE(consistent.imbalance.size() == 10);
    for (const double v : consistent.imbalance)
      CHECK(v == Approx((46.0 - 18.5) / 46.0).epsilon(1e-9));
    CHECK(consistent.warnings == 10);
  }
  SECTION("intensive data without weights is not audited") {
    CHECK(audit_run("intensive", 0.0, 0.0, "consistent").imbalance.empty());
  }
}
