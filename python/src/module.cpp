// The module object, the version, the translation of C++ errors into partita's Python exception
// classes (partita/_errors.py), the log level and check().
#include "module.hpp"

#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "partita/adapters/register_all.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/version.hpp"
#include "partita/run/case_run.hpp"

namespace py = pybind11;

namespace partita::python {

const coupling::Registries& stock_registries() {
  static const coupling::Registries r = [] {
    coupling::Registries made;
    coupling::register_builtin(made);
    adapters::register_all(made);
    return made;
  }();
  return r;
}

std::vector<SourceLocation> override_origins(const std::vector<std::string>& overrides,
                                             const std::string& call) {
  std::vector<SourceLocation> origins;
  for (const auto& o : overrides) {
    SourceLocation where;
    where.file = "partita." + call + "(set={'" + o.substr(0, o.find('=')) + "': ...})";
    origins.push_back(where);
  }
  return origins;
}

void refuse_plugins(const std::string& case_file, const std::vector<std::string>& overrides) {
  if (!run::case_plugins(case_file, overrides).empty())
    throw Error(case_file +
                ": the case loads solver plugins (plugins:), which the Python module does not "
                "load; run it with the partita executable (partita run " +
                case_file + ")");
}

namespace {

// Raise partita._errors.<kind>(message, file, line, column, key, detail).
void raise(const char* kind, const std::string& message, const SourceLocation& where = {},
           const std::string& key = {}, const std::string& detail = {}) {
  py::object cls = py::module_::import("partita._errors").attr(kind);
  py::object error = cls(message, where.file, where.line, where.column, key, detail);
  PyErr_SetObject(cls.ptr(), error.ptr());
}

// What the `partita` executable prints for each kind of failure, as Python exceptions: a user
// error at a key of an input file is a CaseError, any other user error an Error; a condition
// partita does not check for is an InternalError whose text names no internals (the detail goes
// to the debug log), as the executable's message does.
void translate(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const py::error_already_set&) {
    throw;  // a Python exception raised inside (a callback's) passes unchanged
  } catch (const Error& e) {
    const bool located = !e.where().file.empty() || !e.key_path().empty();
    raise(located ? "CaseError" : "Error", e.what(), e.where(), e.key_path(), e.detail());
  } catch (const std::bad_alloc&) {
    raise("Error",
          "out of memory: the case needs more memory than this machine gives the process (fewer "
          "particles or elements, or a machine with more memory)");
  } catch (const std::exception& e) {
    log::get("app")->debug("unexpected exception: {}", e.what());
    raise("InternalError",
          "the run stopped on a condition that partita does not check for yet; this is a bug, "
          "please report it with the case file and the output of the same call with "
          "partita.set_log_level('debug')");
  }
}

py::dict check(const std::string& case_file, const std::vector<std::string>& overrides) {
  refuse_plugins(case_file, overrides);
  run::RunOptions options;
  options.check_only = true;
  options.overrides = overrides;
  options.override_origins = override_origins(overrides, "check");
  py::dict out;
  std::vector<std::string> external;
  std::string name, output_dir;
  const auto regs = registries();
  {
    py::gil_scoped_release release;  // a check builds every participant: it can take seconds
    run::CaseRun c(case_file, *regs, options);
    external = c.external_participants();
    name = c.name();
    output_dir = c.output_dir().string();
  }
  out["name"] = name;
  out["output_dir"] = output_dir;
  out["external_participants"] = external;
  return out;
}

}  // namespace

}  // namespace partita::python

PYBIND11_MODULE(_partita, m) {
  using namespace partita::python;
  m.doc() = "partita's run library from Python (use the package `partita`, not this module)";
  py::register_exception_translator(&translate);
  m.def("version", [] { return std::string(partita::version()); });
  m.def(
      "set_log_level",
      [](const std::string& level) { partita::log::set_level(partita::log::parse_level(level)); },
      py::arg("level"));
  m.def("check", &check, py::arg("case_file"), py::arg("overrides"));
  m.def("solver_names", [] {
    std::vector<std::string> names;
    for (const auto& e : registries()->solvers.entries()) names.push_back(e.name);
    return names;
  });
  bind_run(m);
  bind_solver(m);
#ifdef PARTITA_PYTHON_MPI
  bind_external(m);
#else
  m.attr("has_mpi") = false;
#endif
}
