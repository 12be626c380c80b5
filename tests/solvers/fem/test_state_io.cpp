// Binary state files: write -> read -> restore -> continue is bit-identical to never stopping;
// bad magic, version and truncation are reported.
#include <catch2/catch.hpp>
#include <cstring>
#include <memory>
#include <sstream>

#include "fem_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/state_io.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

// A plastic cantilever hit by a tip load (implicit Newmark with Newton, or explicit).
Model plastic_cantilever(double ramp_time = 1e-3, double traction = 4e7) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.1, 0.1), {6, 1, 1}, ElementType::Hex8}));
  m.set_material_law(
      std::make_shared<J2PlasticityLaw>(200e9, 0.3, 7850.0, HardeningCurve::linear(250e6, 2e9)));
  m.fix("xmin");
  m.add_traction("xmax", Vec3(0, 0, -traction),
                 [ramp_time](double t) { return std::min(1.0, t / ramp_time); });
  return m;
}

void run_and_compare(const SolverOptions& opt, double dt, double ramp_time, double traction) {
  StructuralSolver a(plastic_cantilever(ramp_time, traction), opt);
  for (int k = 0; k < 5; ++k) a.step(dt);
  // coupling loads are part of the state
  a.set_nodal_forces({0, 5}, MatrixX3::Constant(2, 3, 10.0));
  std::stringstream file(std::ios::in | std::ios::out | std::ios::binary);
  write_state(file, a.save_state());
  for (int k = 0; k < 5; ++k) a.step(dt);

  StructuralSolver b(plastic_cantilever(ramp_time, traction), opt);
  b.restore_state(read_state(file));
  for (int k = 0; k < 5; ++k) b.step(dt);
  CHECK(a.time() == b.time());
  CHECK(a.step_count() == b.step_count());
  // bit-identical: exact comparisons
  CHECK((a.displacement().array() == b.displacement().array()).all());
  CHECK((a.velocity().array() == b.velocity().array()).all());
  CHECK((a.acceleration().array() == b.acceleration().array()).all());
  CHECK(a.save_state().material_state == b.save_state().material_state);
  CHECK(a.plastic_work() == b.plastic_work());
  CHECK(a.external_work() == b.external_work());
  CHECK(a.plastic_work() > 0.0);  // the history mattered
}

}  // namespace

TEST_CASE("state file: write, read, continue is bit-identical (J2, Newmark and explicit)",
          "[fem][state]") {
  SECTION("implicit Newmark with Newton") {
    SolverOptions opt;
    run_and_compare(opt, 2e-4, 1e-3, 4e7);
  }
  SECTION("explicit central difference") {
    SolverOptions opt;
    opt.mass = MassType::Lumped;
    opt.integrator = Integrator::CentralDifference;
    StructuralSolver probe(plastic_cantilever(), opt);
    // a step load well beyond yield on the tip face: the tip elements yield at once
    run_and_compare(opt, 0.5 * probe.stable_time_step(), 1e-12, 1e9);
  }
}

TEST_CASE("state file: bad magic, unknown version and truncation are errors", "[fem][state]") {
  StructuralSolver s(plastic_cantilever());
  s.step(1e-4);
  std::stringstream good(std::ios::in | std::ios::out | std::ios::binary);
  write_state(good, s.save_state());
  const std::string bytes = good.str();

  std::string bad_magic = bytes;
  bad_magic[0] = 'X';
  std::istringstream in1(bad_magic);
  CHECK_THROWS_WITH(read_state(in1), Catch::Contains("magic"));

  std::string bad_version = bytes;
  const std::uint32_t v = 99;
  std::memcpy(bad_version.data() + 8, &v, sizeof v);
  std::istringstream in2(bad_version);
  CHECK_THROWS_WITH(read_state(in2), Catch::Contains("version 99"));

  for (std::size_t cut : {std::size_t{4}, std::size_t{30}, bytes.size() / 2, bytes.size() - 1}) {
    std::istringstream in3(bytes.substr(0, cut));
    CHECK_THROWS_WITH(read_state(in3), Catch::Contains("truncated"));
  }
  // a state of another model
  StructuralSolver other(Model(make_box_mesh({})));
  std::istringstream in4(bytes);
  CHECK_THROWS_AS(other.restore_state(read_state(in4)), Error);
}
