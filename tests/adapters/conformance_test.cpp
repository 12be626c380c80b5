// The Solver contract, checked on every registered adapter: meshes are non-empty and their data
// well-formed, the stable time step is positive, write() returns N x C values, read() accepts
// them, checkpoint/restore returns a bit-identical state (the same window repeated gives the
// same outputs), time advances by dt, output files and monitors exist and are finite.
// Every registered solver needs a sample configuration below: a new adapter without one fails.

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include "dem_adapter_support.hpp"
#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"

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

// Deterministic, non-trivial input of the right shape: small values (e.g. a displacement of a
// few micrometres, a pressure of a few pascals) so that every solver stays in its valid range.
Eigen::MatrixXd input(const InterfaceMesh& m, const DataSpec& d, double scale) {
  // Fields that must stay near a reference value (a tube's cross-section) get it as baseline.
  const double base = d.name == "cross_section_area" ? 1.0 : 0.0;
  Eigen::MatrixXd v = Eigen::MatrixXd::Constant(m.mesh.size(), d.components, base);
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    for (Eigen::Index k = 0; k < v.cols(); ++k)
      v(i, k) += scale * (1e-6 * static_cast<double>((i * 7 + k * 3) % 5));
  return v;
}

// Advance one "window" of n steps with inputs, and collect every written field.
std::vector<Eigen::MatrixXd> window(Solver& s, double dt, int n) {
  for (int k = 0; k < n; ++k) {
    for (const auto& m : s.meshes())
      for (const auto& d : m.reads) s.read(m.mesh.name(), d.name, input(m, d, 1.0 + k));
    s.advance(dt);
  }
  std::vector<Eigen::MatrixXd> out;
  for (const auto& m : s.meshes())
    for (const auto& d : m.writes) {
      Eigen::MatrixXd v;
      s.write(m.mesh.name(), d.name, v);
      out.push_back(v);
    }
  return out;
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
                                              << "' to tests/adapters/conformance_test.cpp");
      REQUIRE(it != samples().end());
      config::Node node = config::Node::load_string(it->second, entry.name + ".yaml");
      if (entry.spec) {
        auto spec = std::make_shared<config::Spec>(*entry.spec);
        if (!spec->find("solver")) spec->string("solver", "name").required();
        node = node.validated(spec);
      }
      SolverContext ctx{"p", node, fs::path(PARTITA_SOURCE_DIR), out, 1};
      std::unique_ptr<Solver> s = entry.factory(ctx);
      REQUIRE(s);

      // meshes: non-empty, named, with data of positive width
      REQUIRE_FALSE(s->meshes().empty());
      for (const auto& m : s->meshes()) {
        CHECK_FALSE(m.mesh.name().empty());
        CHECK(m.mesh.size() > 0);
        CHECK(m.reads.size() + m.writes.size() > 0);
        for (const auto* list : {&m.reads, &m.writes})
          for (const auto& d : *list) CHECK(d.components > 0);
      }

      const double dt_stable = s->stable_time_step();
      CHECK(dt_stable > 0.0);
      const double dt = std::isfinite(dt_stable) ? 0.5 * dt_stable : 1e-4;
      CHECK(s->time() == 0.0);

      // write() gives N x C for every written field
      for (const auto& m : s->meshes())
        for (const auto& d : m.writes) {
          Eigen::MatrixXd v;
          s->write(m.mesh.name(), d.name, v);
          CHECK(v.rows() == m.mesh.size());
          CHECK(v.cols() == d.components);
          CHECK(v.allFinite());
        }

      // checkpoint / restore: repeating a window gives bit-identical outputs and time
      window(*s, dt, 2);
      s->save_checkpoint();
      const double t0 = s->time();
      const auto first = window(*s, dt, 3);
      CHECK(s->time() == Approx(t0 + 3 * dt).epsilon(1e-12));
      s->restore_checkpoint();
      CHECK(s->time() == t0);
      const auto again = window(*s, dt, 3);
      REQUIRE(first.size() == again.size());
      for (std::size_t i = 0; i < first.size(); ++i)
        CHECK((first[i].array() == again[i].array()).all());

      // restart files: a fresh solver built from the same configuration and read from what
      // this one wrote continues bit for bit (as the checkpoint does, in another process)
      if (s->supports_restart()) {
        std::stringstream file;
        BinaryWriter w(file);
        s->write_restart(w);
        REQUIRE(w.good());
        std::unique_ptr<Solver> fresh = entry.factory(ctx);
        BinaryReader rd(file, "conformance");
        fresh->read_restart(rd);
        CHECK(fresh->time() == s->time());
        const auto a = window(*s, dt, 3);
        const auto b = window(*fresh, dt, 3);
        REQUIRE(a.size() == b.size());
        for (std::size_t i = 0; i < a.size(); ++i) CHECK((a[i].array() == b[i].array()).all());
        // a truncated file is an error, never a crash or a half-read state
        std::stringstream cut(file.str().substr(0, file.str().size() / 2));
        BinaryReader rc(cut, "cut");
        std::unique_ptr<Solver> other = entry.factory(ctx);
        CHECK_THROWS_AS(other->read_restart(rc), Error);
      }
      CHECK(s->check_state().empty());

      // output and monitors
      s->write_output(OutputFrame{out / "vtk", "p_" + entry.name, 1, s->time(), {}});
      for (const auto& [series, file] : s->output_files()) {
        INFO("output file " << file);
        CHECK(fs::exists(out / "vtk" / file));
        CHECK(fs::file_size(out / "vtk" / file) > 0);
      }
      for (const auto& mv : s->monitors()) {
        INFO("monitor " << mv.name);
        CHECK_FALSE(mv.name.empty());
        CHECK(std::isfinite(mv.value));
        // every reported quantity is on the solver's `partita docs` page, with its unit
        const auto doc =
            std::find_if(entry.quantities.begin(), entry.quantities.end(),
                         [&](const QuantityDoc& d) { return quantity_matches(d, mv.name); });
        INFO("document it in the solver's registration (adapters/src/adapters.cpp)");
        REQUIRE(doc != entry.quantities.end());
        CHECK(doc->unit == mv.unit);
      }
      // monitor_values(names), what the core asks each window: exactly the named quantities,
      // with the values and units monitors() gives (a solver may compute only those asked)
      for (const auto& mv : s->monitors()) {
        INFO("monitor " << mv.name);
        const auto one = s->monitor_values({mv.name});
        REQUIRE(one.size() == 1);
        CHECK(one[0].name == mv.name);
        CHECK(one[0].unit == mv.unit);
        CHECK(one[0].value == mv.value);
      }
      CHECK(s->monitor_values({"no_such_quantity"}).empty());
      s->finalize();
    }
  }
  fs::remove_all(out);
}
