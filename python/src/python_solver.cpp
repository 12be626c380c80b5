// Solvers written in Python: partita.register_solver(name, factory) adds `name` to the registry
// of solvers the module's runs use, and a case that names it as `solver:` gets a PythonSolver,
// the trampoline from partita's Solver contract to the Python object the factory returned
// (partita/_solver.py: the base class, Mesh, Field and the factories by name).
//
// The run works with the GIL released (run.cpp); each call of the trampoline takes it for the
// call into Python. Fields cross as numpy arrays: what read() gets is a read-only view of the
// core's matrix, valid during that call only; what write() returns is copied into the core's
// matrix (and checked: shape, finite values). A Python exception in any call, a bad shape or a
// non-finite value stops the run with a partita::Error that names the participant, the solver
// and the Python exception's type, text and innermost frame.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "module.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/solver.hpp"

namespace py = pybind11;

namespace partita::python {

namespace {

// The registries the module's runs use: the stock ones and the solvers registered from Python.
// Replaced, never changed in place, under the GIL (a run holds its own snapshot).
std::shared_ptr<const coupling::Registries>& current_registries() {
  static std::shared_ptr<const coupling::Registries> r = std::make_shared<coupling::Registries>(
      stock_registries());
  return r;
}

std::vector<std::string>& python_solver_names() {
  static std::vector<std::string> names;
  return names;
}

// "ValueError: text (file.py:12 in advance)" of the Python exception being handled.
std::string exception_text(py::error_already_set& e) {
  std::string text;
  try {
    const py::object type = e.type(), value = e.value(), trace = e.trace();
    text = py::str(type.attr("__name__")).cast<std::string>();
    const std::string message = py::str(value).cast<std::string>();
    if (!message.empty()) text += ": " + message;
    if (!trace.is_none()) {
      const py::list frames = py::module_::import("traceback").attr("extract_tb")(trace);
      if (!frames.empty()) {
        const py::object last = frames[frames.size() - 1];
        text += fmt::format(" ({}:{} in {})", py::str(last.attr("filename")).cast<std::string>(),
                            last.attr("lineno").cast<long>(),
                            py::str(last.attr("name")).cast<std::string>());
      }
    }
  } catch (py::error_already_set&) {
    text = e.what();
  }
  return text;
}

// A YAML node as Python values: maps as dicts, sequences as lists, scalars as int, float, bool
// or str (as YAML text: "20 kPa" stays a string; partita.quantity() converts it to SI).
py::object to_python(const config::Node& n) {
  if (n.is_map()) {
    py::dict d;
    for (const std::string& k : n.keys()) d[py::str(k)] = to_python(n[k]);
    return d;
  }
  if (n.is_sequence()) {
    py::list l;
    for (const config::Node& item : n.items()) l.append(to_python(item));
    return l;
  }
  if (!n.defined()) return py::none();
  return py::module_::import("partita._solver").attr("_scalar")(n.as_string());
}

class PythonSolver : public Solver {
 public:
  // Built under the GIL.
  PythonSolver(std::string solver, std::string participant, py::object object,
               config::Node config)
      : who_("participant '" + participant + "' (Python solver '" + solver + "')"),
        object_(std::move(object)),
        config_(std::move(config)) {
    for (const char* required : {"meshes", "read", "write", "advance", "time", "save_checkpoint",
                                 "restore_checkpoint"})
      if (!py::hasattr(object_, required))
        throw Error(who_ + ": the object its factory returned has no method " + required +
                    "() (derive it from partita.Solver, docs/python.md)");
    restart_ = py::hasattr(object_, "write_restart") && py::hasattr(object_, "read_restart");
  }

  ~PythonSolver() override {
    py::gil_scoped_acquire gil;
    object_ = py::object();
  }

  const std::vector<InterfaceMesh>& meshes() const override {
    if (!meshes_) {
      std::vector<InterfaceMesh> made;
      call("meshes()", [&] {
        const py::object list = object_.attr("meshes")();
        for (const py::handle m : list) made.push_back(to_mesh(m));
      });
      meshes_ = std::move(made);
    }
    return *meshes_;
  }

  std::vector<MeshRequest> mesh_requests() const override {
    std::vector<MeshRequest> out;
    if (!has("mesh_requests")) return out;
    call("mesh_requests()", [&] {
      for (const py::handle r : object_.attr("mesh_requests")()) {
        const auto pair = r.cast<std::pair<std::string, std::string>>();
        out.push_back(MeshRequest{pair.first, pair.second, config_});  // messages: its section
      }
    });
    return out;
  }

  void receive_mesh(const std::string& name, const Mesh& mesh) override {
    call("receive_mesh()", [&] {
      py::array_t<double> points(std::vector<py::ssize_t>{mesh.size(), 3});
      auto p = points.mutable_unchecked<2>();
      for (Eigen::Index i = 0; i < mesh.size(); ++i)
        for (int j = 0; j < 3; ++j) p(i, j) = mesh.points()(i, j);
      py::array_t<int> triangles(std::vector<py::ssize_t>{mesh.num_triangles(), 3});
      auto t = triangles.mutable_unchecked<2>();
      for (Eigen::Index i = 0; i < mesh.num_triangles(); ++i)
        for (int j = 0; j < 3; ++j) t(i, j) = mesh.triangles()(i, j);
      object_.attr("receive_mesh")(name, points, triangles);
    });
  }

  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override {
    call("read()", [&] {
      // A read-only view of the core's column-major matrix: (n,) for one component, else (n, C).
      const py::capsule owner(&values, [](void*) {});
      py::array view;
      if (values.cols() == 1)
        view = py::array(py::dtype::of<double>(), {values.rows()}, {Eigen::Index(sizeof(double))},
                         values.data(), owner);
      else
        view = py::array(py::dtype::of<double>(), {values.rows(), values.cols()},
                         {Eigen::Index(sizeof(double)), Eigen::Index(sizeof(double)) * values.rows()},
                         values.data(), owner);
      view.attr("flags").attr("writeable") = false;
      object_.attr("read")(py::str(mesh.data(), mesh.size()), py::str(data.data(), data.size()),
                           view);
    });
  }

  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override {
    const auto [rows, cols] = shape_of(mesh, data);
    values.resize(rows, cols);
    call("write()", [&] {
      const py::object got = object_.attr("write")(py::str(mesh.data(), mesh.size()),
                                                   py::str(data.data(), data.size()));
      const auto a = py::array_t<double, py::array::forcecast>::ensure(got);
      const std::string what = fmt::format("write('{}', '{}')", mesh, data);
      if (!a)
        throw Error(fmt::format("{}: {} returned no array of numbers", who_, what));
      const bool fits = (a.ndim() == 1 && a.shape(0) == rows && cols == 1) ||
                        (a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == cols);
      if (!fits) {
        std::string shape;
        for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
        throw Error(fmt::format("{}: {} returned an array of shape ({}), not ({}{})", who_, what,
                                shape, rows, cols == 1 ? std::string(",") : ", " + std::to_string(cols)));
      }
      const double* p = a.data();
      const py::ssize_t s0 = a.strides(0) / py::ssize_t(sizeof(double));
      const py::ssize_t s1 = a.ndim() == 2 ? a.strides(1) / py::ssize_t(sizeof(double)) : 0;
      for (Eigen::Index i = 0; i < rows; ++i)
        for (Eigen::Index j = 0; j < cols; ++j) {
          const double v = p[i * s0 + j * s1];
          if (!std::isfinite(v))
            throw Error(fmt::format("{}: {} returned {} at point {}{}: the solver's state is no "
                                    "longer physical", who_, what, v, i,
                                    cols > 1 ? fmt::format(", component {}", j) : ""));
          values(i, j) = v;
        }
    });
  }

  double stable_time_step() const override {
    if (!has("stable_time_step")) return std::numeric_limits<double>::infinity();
    double dt = 0.0;
    call("stable_time_step()", [&] { dt = object_.attr("stable_time_step")().cast<double>(); });
    return dt;
  }

  void advance(double dt) override { call("advance()", [&] { object_.attr("advance")(dt); }); }

  double time() const override {
    double t = 0.0;
    call("time()", [&] { t = object_.attr("time")().cast<double>(); });
    return t;
  }

  void save_checkpoint() override {
    call("save_checkpoint()", [&] { object_.attr("save_checkpoint")(); });
  }
  void restore_checkpoint() override {
    call("restore_checkpoint()", [&] { object_.attr("restore_checkpoint")(); });
  }

  bool supports_restart() const override { return restart_; }
  void write_restart(BinaryWriter& out) const override {
    std::string bytes;
    call("write_restart()", [&] { bytes = object_.attr("write_restart")().cast<py::bytes>(); });
    out.section("python-solver");
    out.bytes(bytes);
  }
  void read_restart(BinaryReader& in) override {
    in.expect_section("python-solver");
    const std::string bytes = in.bytes();
    call("read_restart()", [&] { object_.attr("read_restart")(py::bytes(bytes)); });
  }

  void write_output(const OutputFrame& frame) override {
    if (!has("write_output")) return;
    call("write_output()", [&] {
      const py::object frame_type = py::module_::import("partita._solver").attr("OutputFrame");
      const py::object files = object_.attr("write_output")(frame_type(
          frame.vtk_directory.string(), frame.prefix, frame.index, frame.time));
      files_.clear();
      if (!files.is_none())
        for (const py::handle f : files) files_.push_back(f.cast<std::pair<std::string, std::string>>());
    });
  }
  std::vector<std::pair<std::string, std::string>> output_files() const override { return files_; }

  std::vector<MonitorValue> monitors() const override {
    std::vector<MonitorValue> out;
    if (!has("monitors")) return out;
    call("monitors()", [&] {
      const py::object got = object_.attr("monitors")();
      if (got.is_none()) return;
      for (const auto& [key, item] : got.cast<py::dict>()) {
        MonitorValue v;
        v.name = py::str(key).cast<std::string>();
        if (py::isinstance<py::tuple>(item)) {
          const auto t = item.cast<py::tuple>();
          v.value = t[0].cast<double>();
          if (t.size() > 1) v.unit = t[1].cast<std::string>();
        } else {
          v.value = item.cast<double>();
        }
        out.push_back(std::move(v));
      }
    });
    return out;
  }

  std::string check_state() const override {
    if (!has("check_state")) return {};
    std::string text;
    call("check_state()", [&] {
      const py::object got = object_.attr("check_state")();
      if (!got.is_none()) text = py::str(got).cast<std::string>();
    });
    return text.empty() ? text : who_ + ": " + text;
  }

  std::optional<double> interface_work(std::string_view mesh) const override {
    if (!has("interface_work")) return std::nullopt;
    std::optional<double> work;
    call("interface_work()", [&] {
      const py::object got = object_.attr("interface_work")(py::str(mesh.data(), mesh.size()));
      if (!got.is_none()) work = got.cast<double>();
    });
    return work;
  }

  void finalize() override {
    if (has("finalize")) call("finalize()", [&] { object_.attr("finalize")(); });
  }

 private:
  // Run f with the GIL; a Python exception (or a cast that fails) becomes a partita::Error
  // naming the solver and the call.
  template <class F>
  void call(const char* what, F&& f) const {
    py::gil_scoped_acquire gil;
    try {
      f();
    } catch (py::error_already_set& e) {
      throw Error(who_ + ": " + what + " raised " + exception_text(e));
    } catch (const py::cast_error& e) {
      throw Error(who_ + ": " + what + " returned a value of the wrong type (" + e.what() + ")");
    }
  }

  bool has(const char* name) const {
    py::gil_scoped_acquire gil;
    return py::hasattr(object_, name);
  }

  std::pair<Eigen::Index, Eigen::Index> shape_of(std::string_view mesh, std::string_view data) const {
    for (const InterfaceMesh& m : meshes())
      if (m.mesh.name() == mesh)
        for (const DataSpec& d : m.writes)
          if (d.name == data) return {m.mesh.size(), d.components};
    throw Error(fmt::format("{}: asked to write '{}' on mesh '{}', which its meshes() do not list",
                            who_, data, mesh));
  }

  InterfaceMesh to_mesh(py::handle m) const { return to_interface_mesh(m, who_); }

  std::string who_;
  py::object object_;
  config::Node config_;  // the participant's section, where messages about its requests point
  bool restart_ = false;
  mutable std::optional<std::vector<InterfaceMesh>> meshes_;
  std::vector<std::pair<std::string, std::string>> files_;
};

// Add `name` to the registries (the Python factory itself stays in partita._solver).
void add_solver(const std::string& name, const std::string& doc) {
  auto& names = python_solver_names();
  if (std::find(names.begin(), names.end(), name) != names.end()) return;  // a new factory
  if (current_registries()->solvers.contains(name))
    throw Error("register_solver('" + name + "'): partita has a solver of that name; choose another");
  auto next = std::make_shared<coupling::Registries>(*current_registries());
  next->solvers.add(name, doc.empty() ? "a solver written in Python" : doc,
                    [name](const SolverContext& c) -> std::unique_ptr<Solver> {
                      py::gil_scoped_acquire gil;
                      const std::string who =
                          "participant '" + c.name + "' (Python solver '" + name + "')";
                      try {
                        py::object made = py::module_::import("partita._solver").attr("_build")(
                            name, c.name, to_python(c.config), c.case_dir.string(),
                            c.output_dir.string(), c.threads);
                        return std::make_unique<PythonSolver>(name, c.name, std::move(made), c.config);
                      } catch (py::error_already_set& e) {
                        throw Error(who + ": its factory raised " + exception_text(e));
                      }
                    });
  names.push_back(name);
  current_registries() = std::move(next);
}

}  // namespace

std::shared_ptr<const coupling::Registries> registries() { return current_registries(); }

void refuse_python_solvers(const std::string& case_file, const std::vector<std::string>& overrides) {
  const std::vector<std::string>& names = python_solver_names();
  if (names.empty()) return;
  const config::Node root = config::Node::load_file(case_file, overrides);
  if (!root.has("participants") || !root["participants"].is_map()) return;
  for (const std::string& p : root["participants"].keys()) {
    const config::Node pn = root["participants"][p];
    if (!pn.is_map() || !pn.has("solver")) continue;
    const std::string solver = pn["solver"].as_string();
    if (std::find(names.begin(), names.end(), solver) != names.end())
      pn["solver"].fail("'" + solver +
                        "' is a solver registered in Python, which a sweep cannot use: its "
                        "variants run as partita processes; run them with partita.run in a loop");
  }
}

InterfaceMesh to_interface_mesh(py::handle m, const std::string& who) {
  InterfaceMesh im;
  const std::string name = py::str(m.attr("name")).cast<std::string>();
  const auto pts = py::array_t<double, py::array::forcecast>::ensure(m.attr("points"));
  if (!pts || pts.ndim() != 2 || pts.shape(1) != 3)
    throw Error(who + ": mesh '" + name + "': points must be an array of shape (n, 3)");
  Mesh::Points points(pts.shape(0), 3);
  const auto p = pts.unchecked<2>();
  for (py::ssize_t i = 0; i < pts.shape(0); ++i)
    for (int j = 0; j < 3; ++j) points(i, j) = p(i, j);
  Mesh::Triangles triangles(0, 3);
  const py::object tri = m.attr("triangles");
  if (!tri.is_none()) {
    const auto t = py::array_t<int, py::array::forcecast>::ensure(tri);
    if (!t || t.ndim() != 2 || t.shape(1) != 3)
      throw Error(who + ": mesh '" + name + "': triangles must be an array of shape (m, 3)");
    triangles.resize(t.shape(0), 3);
    const auto tv = t.unchecked<2>();
    for (py::ssize_t i = 0; i < t.shape(0); ++i)
      for (int j = 0; j < 3; ++j) triangles(i, j) = tv(i, j);
  }
  im.mesh = Mesh(name, std::move(points), std::move(triangles));
  const py::object weights = m.attr("weights");
  if (!weights.is_none()) {
    const auto w = py::array_t<double, py::array::forcecast>::ensure(weights);
    if (!w || w.ndim() != 1)
      throw Error(who + ": mesh '" + name + "': weights must be an array of shape (n,)");
    im.mesh.set_weights(Eigen::Map<const Eigen::VectorXd>(w.data(), w.shape(0)));
  }
  const auto fields = [&](const char* which) {
    std::vector<DataSpec> out;
    for (const py::handle f : m.attr(which)) {
      DataSpec d;
      d.name = py::str(f.attr("name")).cast<std::string>();
      d.components = f.attr("components").cast<int>();
      d.unit = py::str(f.attr("unit")).cast<std::string>();
      const std::string kind = py::str(f.attr("kind")).cast<std::string>();
      if (d.components != 1 && d.components != 3)
        throw Error(who + ": field '" + d.name + "' of mesh '" + name +
                    "': components must be 1 or 3");
      if (kind != "intensive" && kind != "extensive")
        throw Error(who + ": field '" + d.name + "' of mesh '" + name +
                    "': kind must be 'intensive' or 'extensive', not '" + kind + "'");
      d.kind = kind == "extensive" ? DataKind::extensive : DataKind::intensive;
      out.push_back(std::move(d));
    }
    return out;
  };
  im.reads = fields("reads");
  im.writes = fields("writes");
  im.prescribed = m.attr("prescribed").cast<bool>();
  return im;
}

void bind_solver(py::module_& m) {
  m.def("add_solver", &add_solver, py::arg("name"), py::arg("doc"));
  m.def("python_solver_names", [] { return python_solver_names(); });
  m.def(
      "quantity",
      [](const std::string& text, const std::string& unit) {
        std::string why;
        const std::optional<double> v = config::parse_quantity(text, unit, &why);
        if (!v)
          throw Error("quantity('" + text + "', '" + unit + "'): " +
                      (why.empty() ? "not a number with a unit of " + unit : why));
        return *v;
      },
      py::arg("text"), py::arg("unit"));
}

}  // namespace partita::python
