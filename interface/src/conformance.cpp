// The Solver contract check (conformance.hpp).

#include "partita/interface/conformance.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "partita/interface/binary_io.hpp"

namespace partita {

namespace {

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

bool same_bits(const std::vector<Eigen::MatrixXd>& a, const std::vector<Eigen::MatrixXd>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].rows() != b[i].rows() || a[i].cols() != b[i].cols() ||
        !(a[i].array() == b[i].array()).all())
      return false;
  return true;
}

}  // namespace

std::vector<std::string> check_solver_contract(const Registry<SolverFactory>::Entry& entry,
                                               const std::string& sample_yaml,
                                               const std::filesystem::path& case_dir,
                                               const std::filesystem::path& work_dir) {
  namespace fs = std::filesystem;
  std::vector<std::string> failures;
  auto fail = [&](const std::string& what) { failures.push_back(entry.name + ": " + what); };
  config::Node node = config::Node::load_string(sample_yaml, entry.name + ".yaml");
  if (entry.spec) {
    auto spec = std::make_shared<config::Spec>(*entry.spec);
    if (!spec->find("solver")) spec->string("solver", "name").required();
    node = node.validated(spec);
  }
  fs::create_directories(work_dir / "vtk");
  const SolverContext ctx{"p", node, case_dir, work_dir, 1};
  std::unique_ptr<Solver> s = entry.factory(ctx);
  if (!s) {
    fail("the factory returned no solver");
    return failures;
  }

  // meshes: non-empty, named, with data of positive width
  if (s->meshes().empty()) fail("meshes() is empty: a participant exposes at least one mesh");
  for (const auto& m : s->meshes()) {
    if (m.mesh.name().empty()) fail("a mesh has no name");
    if (m.mesh.size() == 0) fail("mesh '" + m.mesh.name() + "' has no points");
    if (m.reads.size() + m.writes.size() == 0)
      fail("mesh '" + m.mesh.name() + "' neither reads nor writes any data");
    for (const auto* list : {&m.reads, &m.writes})
      for (const auto& d : *list)
        if (d.components <= 0)
          fail("data '" + d.name + "' on '" + m.mesh.name() + "' has no components");
  }

  const double dt_stable = s->stable_time_step();
  if (!(dt_stable > 0.0)) fail(fmt::format("stable_time_step() is {}, not > 0", dt_stable));
  const double dt = std::isfinite(dt_stable) && dt_stable > 0.0 ? 0.5 * dt_stable : 1e-4;
  if (s->time() != 0.0) fail(fmt::format("time() starts at {}, not 0", s->time()));

  // write() gives N x C finite values for every written field
  for (const auto& m : s->meshes())
    for (const auto& d : m.writes) {
      Eigen::MatrixXd v;
      s->write(m.mesh.name(), d.name, v);
      if (v.rows() != static_cast<Eigen::Index>(m.mesh.size()) || v.cols() != d.components)
        fail(fmt::format("write('{}', '{}') gives {} x {} values, not {} x {}", m.mesh.name(),
                         d.name, v.rows(), v.cols(), m.mesh.size(), d.components));
      else if (!v.allFinite())
        fail("write('" + m.mesh.name() + "', '" + d.name + "') gives non-finite values");
    }

  // checkpoint / restore: repeating a window gives bit-identical outputs and time
  window(*s, dt, 2);
  s->save_checkpoint();
  const double t0 = s->time();
  const auto first = window(*s, dt, 3);
  // time() after three steps is their sum to round-off (a few ulps): 1e-12, tighter than the
  // coupling's window tolerance (TimeWindow::tolerance, 1e-9, which also absorbs the user's
  // decimal times such as 0.3 / 0.1); interface/ cannot name the coupling's constant
  if (std::abs(s->time() - (t0 + 3 * dt)) > 1e-12 * std::max(1.0, std::abs(t0 + 3 * dt)))
    fail(fmt::format("time() advanced to {} after 3 steps of {} from {}", s->time(), dt, t0));
  s->restore_checkpoint();
  if (s->time() != t0) fail("restore_checkpoint() does not restore time()");
  const auto again = window(*s, dt, 3);
  if (!same_bits(first, again))
    fail("a window repeated after restore_checkpoint() gives other outputs (not bit-identical)");

  // restart: a fresh solver read from what this one wrote continues bit for bit
  if (s->supports_restart()) {
    std::stringstream file;
    BinaryWriter w(file);
    s->write_restart(w);
    if (!w.good()) fail("write_restart() left the stream in a failed state");
    std::unique_ptr<Solver> fresh = entry.factory(ctx);
    BinaryReader rd(file, "conformance");
    fresh->read_restart(rd);
    if (fresh->time() != s->time()) fail("a solver read from a restart stream has another time()");
    if (!same_bits(window(*s, dt, 3), window(*fresh, dt, 3)))
      fail("a solver read from a restart stream does not continue bit for bit");
    std::stringstream cut(file.str().substr(0, file.str().size() / 2));
    BinaryReader rc(cut, "cut");
    std::unique_ptr<Solver> other = entry.factory(ctx);
    bool refused = false;
    try {
      other->read_restart(rc);
    } catch (const Error&) {
      refused = true;
    }
    if (!refused) fail("read_restart() of a truncated stream did not throw partita::Error");
  }
  if (const std::string why = s->check_state(); !why.empty())
    fail("check_state() finds a healthy state wrong: " + why);

  // output and monitors
  s->write_output(OutputFrame{work_dir / "vtk", "p_" + entry.name, 1, s->time(), {}});
  for (const auto& [series, file] : s->output_files()) {
    std::error_code ec;
    if (!fs::exists(work_dir / "vtk" / file) || fs::file_size(work_dir / "vtk" / file, ec) == 0)
      fail("output file " + file + " of series " + series + " is missing or empty");
  }
  const auto monitors = s->monitors();
  for (const auto& mv : monitors) {
    if (mv.name.empty()) fail("a monitor quantity has no name");
    if (!std::isfinite(mv.value)) fail("monitor " + mv.name + " is not finite");
    const auto doc =
        std::find_if(entry.quantities.begin(), entry.quantities.end(),
                     [&](const QuantityDoc& d) { return quantity_matches(d, mv.name); });
    if (doc == entry.quantities.end())
      fail("monitor " + mv.name +
           " is not documented: list it with its unit in the solver's registration");
    else if (doc->unit != mv.unit)
      fail("monitor " + mv.name + " reports unit '" + mv.unit + "', documented '" + doc->unit +
           "'");
    const auto one = s->monitor_values({mv.name});
    if (one.size() != 1 || one[0].name != mv.name || one[0].unit != mv.unit ||
        !(one[0].value == mv.value || (std::isnan(one[0].value) && std::isnan(mv.value))))
      fail("monitor_values({" + mv.name + "}) does not give what monitors() gives");
  }
  if (!s->monitor_values({"no_such_quantity"}).empty())
    fail("monitor_values() answers for an unknown quantity");
  s->finalize();
  return failures;
}

}  // namespace partita
