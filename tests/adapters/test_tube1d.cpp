// The tube adapters under the Solver contract, and the elastic tube case (shortened) through the
// coupling core: IQN-ILS must converge in every window with fewer iterations than Aitken.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "partita/adapters/register_all.hpp"
#include "partita/run/case_run.hpp"

using namespace partita;
namespace fs = std::filesystem;

namespace {

// Options by name (robust to fields added later).
run::RunOptions run_options(const std::filesystem::path& dir, bool check_only) {
  run::RunOptions o;
  o.output_dir = dir;
  o.check_only = check_only;
  return o;
}

coupling::Registries registries() {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  return r;
}

// The case file with the end time replaced (t = 1 -> `end`), written to a scratch folder.
fs::path shortened(const std::string& name, const std::string& end) {
  std::ifstream in(fs::path(PARTITA_SOURCE_DIR) / "cases/elastic_tube_1d" / (name + ".yaml"));
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  const auto at = text.find("end: 1.0");
  REQUIRE(at != std::string::npos);
  text.replace(at, 8, "end: " + end);
  const fs::path dir =
      fs::temp_directory_path() / ("partita_tube_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file) << text;
  return file;
}

std::unique_ptr<Solver> make(const coupling::Registries& r, const std::string& solver) {
  const auto& e = r.solvers.get(solver);
  config::Node n = config::Node::load_string("{solver: " + solver + "}");
  auto spec = std::make_shared<config::Spec>(*e.spec);
  spec->string("solver", "name");
  SolverContext ctx{"p", n.validated(spec), ".", ".", 1};
  return e.factory(ctx);
}

}  // namespace

TEST_CASE("Tube adapters follow the Solver contract, checkpoint/restore is bit-identical",
          "[adapters][tube1d]") {
  const auto r = registries();
  for (const char* name : {"tube1d-fluid", "tube1d-solid"}) {
    auto s = make(r, name);
    REQUIRE(s->meshes().size() == 1);
    CHECK(s->meshes()[0].mesh.size() == 101);
    CHECK(s->meshes()[0].mesh.points()(100, 0) == Approx(10.0));
    CHECK(s->stable_time_step() > 0.0);
    Eigen::MatrixXd out;
    const std::string writes = s->meshes()[0].writes[0].name, reads = s->meshes()[0].reads[0].name;
    const Eigen::MatrixXd in =
        Eigen::MatrixXd::Constant(101, 1, writes == "pressure" ? 1.001 : 50.0);
    s->save_checkpoint();
    s->read("nodes", reads, in);
    s->advance(0.01);
    s->write("nodes", writes, out);
    const Eigen::MatrixXd first = out;
    s->restore_checkpoint();
    CHECK(s->time() == 0.0);
    s->read("nodes", reads, in * 1.01);  // a different iterate in between
    s->advance(0.01);
    s->restore_checkpoint();
    s->read("nodes", reads, in);
    s->advance(0.01);
    s->write("nodes", writes, out);
    CHECK((out - first).cwiseAbs().maxCoeff() == 0.0);
    CHECK(!s->monitors().empty());
  }
}

TEST_CASE(
    "Elastic tube (t = 0.1): IQN-ILS converges in every window, with fewer iterations than Aitken",
    "[adapters][tube1d][case]") {
  const auto r = registries();
  const fs::path out =
      fs::temp_directory_path() / ("partita_tube_out_" + std::to_string(::getpid()));
  run::CaseRun iqn(shortened("iqn-ils", "0.1"), r, run_options(out / "iqn", false));
  iqn.run();
  run::CaseRun aitken(shortened("aitken", "0.1"), r, run_options(out / "aitken", false));
  aitken.run();
  const auto& si = iqn.summary();
  const auto& sa = aitken.summary();
  INFO("mean iterations: IQN-ILS " << si.mean_iterations() << ", Aitken " << sa.mean_iterations());
  CHECK(si.windows == 10);
  CHECK(si.unconverged_windows == 0);
  CHECK(si.max_window_iterations == 20);  // preCICE v3: 20 in window 1
  CHECK(si.mean_iterations() < 0.5 * sa.mean_iterations());
  CHECK(fs::exists(out / "iqn" / "coupling.csv"));
  CHECK(fs::exists(out / "iqn" / "tube.csv"));
  CHECK(fs::exists(out / "iqn" / "vtk" / "fluid_tube.pvd"));
}

TEST_CASE("Elastic tube (t = 1): IQN-IMVJ converges in every window and carries the Jacobian on",
          "[adapters][tube1d][case][slow]") {
  // Without information from past windows (IQN-ILS, reused_windows 0) every window starts its
  // model from nothing; IMVJ starts from the previous windows' Jacobian, so it must need clearly
  // fewer iterations over the whole run (the tube's 100 windows, about 0.3 s each way).
  const auto r = registries();
  const fs::path out =
      fs::temp_directory_path() / ("partita_tube_imvj_" + std::to_string(::getpid()));
  const fs::path cases = fs::path(PARTITA_SOURCE_DIR) / "cases/elastic_tube_1d";
  run::CaseRun imvj(cases / "iqn-imvj.yaml", r, run_options(out / "imvj", false));
  imvj.run();
  run::RunOptions o = run_options(out / "ils0", false);
  o.overrides = {"coupling.acceleration.reused_windows=0"};
  run::CaseRun ils0(cases / "iqn-ils.yaml", r, o);
  ils0.run();
  const auto& sm = imvj.summary();
  const auto& s0 = ils0.summary();
  INFO("mean iterations: IQN-IMVJ " << sm.mean_iterations() << ", IQN-ILS without reuse "
                                    << s0.mean_iterations());
  CHECK(sm.windows == 100);
  CHECK(sm.unconverged_windows == 0);
  CHECK(s0.unconverged_windows == 0);
  CHECK(sm.mean_iterations() < 0.6 * s0.mean_iterations());
  fs::remove_all(out);
}

TEST_CASE("Every elastic tube case file validates (check_only)", "[adapters][tube1d][case]") {
  const auto r = registries();
  for (const char* c : {"constant", "aitken", "iqn-ils", "iqn-imvj"}) {
    run::CaseRun run(
        fs::path(PARTITA_SOURCE_DIR) / "cases/elastic_tube_1d" / (std::string(c) + ".yaml"), r,
        run_options("unused", true));
    CHECK(run.window_count() == 100);
  }
}
