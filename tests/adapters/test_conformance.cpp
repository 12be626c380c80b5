// The Solver contract (partita/interface/conformance.hpp), checked on every registered adapter:
// meshes are non-empty and their data well-formed, the stable time step is positive, write()
// returns N x C values, read() accepts them, checkpoint/restore returns a bit-identical state
// (the same window repeated gives the same outputs), time advances by dt, restart streams
// continue bit for bit, output files and monitors exist, are finite and documented.
// Every registered solver needs a sample configuration below: a new adapter without one fails.
// The check also fails when it should: a solver that breaks the contract on purpose.

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "dem_adapter_support.hpp"
#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/conformance.hpp"

using namespace partita;
namespace fs = std::filesystem;

namespace {

const std::map<std::string, std::string>& samples() {
  static const std::map<std::string, std::string> s = {
      {"tube1d-fluid", "solver: tube1d-fluid\ncells: 20\n"},
      {"tube1d-solid", "solver: tube1d-solid\ncells: 20\n"},
      {"fem",
       "solver: fem\n"
       "mesh: {box: {origin: [0, 0, 0.02], size: [0.02, 0.02, 0.002], cells: [4, 4, 1]}}\n"
       "material: {youngs_modulus: 2.5 MPa, poisson_ratio: 0.45, density: 1100}\n"
       "constraints: [{set: all, fix: [x, y]}]\n"
       "loads: [{face: zmax, pressure: 10 kPa}, {gravity: [0, 0, -9.81]}]\n"
       "interfaces: [{name: bottom, face: zmin}]\n"},
      {"dem", test::small_bed_yaml()},
  };
  return s;
}

}  // namespace

TEST_CASE("every registered adapter honours the Solver contract", "[adapters][conformance]") {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  REQUIRE(r.solvers.entries().size() >= 4);
  const fs::path out =
      fs::temp_directory_path() / ("partita_conformance_" + std::to_string(::getpid()));
  fs::create_directories(out / "vtk");
  for (const auto& entry : r.solvers.entries()) {
    DYNAMIC_SECTION("solver " << entry.name) {
      const auto it = samples().find(entry.name);
      INFO("add a sample configuration for '" << entry.name
                                              << "' to tests/adapters/test_conformance.cpp");
      REQUIRE(it != samples().end());
      // the contract itself: partita::check_solver_contract (installed with the package, so
      // that an adapter written out of tree runs the same checks)
      const auto failures =
          check_solver_contract(entry, it->second, fs::path(PARTITA_SOURCE_DIR), out / entry.name);
      for (const auto& f : failures) FAIL_CHECK(f);
    }
  }
  fs::remove_all(out);
}

namespace {

// A solver that breaks the contract on purpose: its checkpoint forgets the state, it reports an
// undocumented monitor and a write() of the wrong shape.
class BrokenSolver final : public Solver {
 public:
  BrokenSolver() {
    InterfaceMesh m;
    Mesh::Points p(2, 3);
    p << 0, 0, 0, 1, 0, 0;
    m.mesh = Mesh("points", p);
    m.writes.push_back(DataSpec{"position", 1, "m", DataKind::intensive});
    m.reads.push_back(DataSpec{"force", 1, "N", DataKind::extensive});
    meshes_.push_back(std::move(m));
  }
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd& v) override {
    f_ = v.sum();
  }
  void write(std::string_view, std::string_view, Eigen::MatrixXd& v) override {
    v = Eigen::MatrixXd::Constant(1, 1, x_);  // one row for a mesh of two points
  }
  void advance(double dt) override {
    x_ += dt * (1.0 + f_);
    t_ += dt;
  }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_t_ = t_; }
  void restore_checkpoint() override { t_ = saved_t_; }  // x_ is not restored
  std::vector<MonitorValue> monitors() const override { return {{"secret", "m", x_}}; }

 private:
  std::vector<InterfaceMesh> meshes_;
  double x_ = 0.0, f_ = 0.0, t_ = 0.0, saved_t_ = 0.0;
};

}  // namespace

TEST_CASE("the contract check finds a solver that breaks it", "[adapters][conformance]") {
  Registry<SolverFactory> r("solver");
  r.add("broken", "breaks the contract", [](const SolverContext&) {
    return std::unique_ptr<Solver>(std::make_unique<BrokenSolver>());
  });
  const fs::path out =
      fs::temp_directory_path() / ("partita_conformance_broken_" + std::to_string(::getpid()));
  const auto failures = check_solver_contract(*r.find("broken"), "solver: broken\n", out, out);
  fs::remove_all(out);
  auto found = [&](const std::string& text) {
    return std::any_of(failures.begin(), failures.end(),
                       [&](const std::string& f) { return f.find(text) != std::string::npos; });
  };
  INFO([&] {
    std::string all;
    for (const auto& f : failures) all += f + "\n";
    return all;
  }());
  CHECK(found("gives 1 x 1 values, not 2 x 1"));
  CHECK(found("not bit-identical"));
  CHECK(found("monitor secret is not documented"));
}
