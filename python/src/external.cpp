// partita::mpi::ExternalParticipant for Python (partita/_external.py wraps it): a Python program
// with its own time loop joins a partita run under mpirun as the C++ API's programs do.
//
// The calls that wait for the rest of the run (initialize, advance, finalize, and closing the
// participant) release the GIL: the API's thread then runs the participant's side of the
// coupling, and calls the program's restart writer, which takes the GIL for that call. Fields
// cross as numpy arrays of shape (n,) for 1 component and (n, 3) for 3: read() returns a new
// array (a copy the program owns), write() copies what it is given.
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "module.hpp"
#include "partita/mpi/external_participant.hpp"

namespace py = pybind11;

namespace partita::python {

namespace {

// A Python object that the API's side may drop without the GIL (the restart writer: the
// participant is destroyed with the GIL released).
struct HeldObject {
  py::object object;
  explicit HeldObject(py::object o) : object(std::move(o)) {}
  ~HeldObject() {
    py::gil_scoped_acquire gil;
    object = py::object();
  }
  HeldObject(const HeldObject&) = delete;
  HeldObject& operator=(const HeldObject&) = delete;
};

// The participant, and what the binding checks before handing values to it.
class External {
 public:
  External(const std::string& participant, const std::string& case_file,
           const std::vector<std::string>& overrides, py::object fortran_comm, double peer_timeout)
      : who_("participant '" + participant + "' (a Python program)") {
    mpi::ExternalOptions options;
    options.overrides = overrides;
    options.peer_timeout = peer_timeout;
    if (!fortran_comm.is_none()) {
      // an mpi4py communicator's handle (comm.py2f()): the same MPI library is loaded
      int initialized = 0;
      MPI_Initialized(&initialized);
      if (!initialized)
        throw Error(who_ +
                    ": a communicator was given but MPI is not initialised (import "
                    "mpi4py.MPI first, or give no communicator)");
      options.comm = MPI_Comm_f2c(fortran_comm.cast<MPI_Fint>());
    }
    p_ = std::make_unique<mpi::ExternalParticipant>(participant, case_file, std::move(options));
  }

  ~External() { close(); }

  void close() {
    if (!p_) return;
    py::gil_scoped_release release;  // the API's thread may still call the restart writer
    p_.reset();
  }

  mpi::ExternalParticipant& get() const {
    if (!p_) throw mpi::UsageError(who_ + ": the participant is closed");
    return *p_;
  }

  void add_mesh(py::handle mesh) {
    InterfaceMesh m = to_interface_mesh(mesh, who_);
    for (const DataSpec& d : m.reads)
      shapes_[{m.mesh.name(), d.name}] = {m.mesh.size(), d.components};
    for (const DataSpec& d : m.writes)
      shapes_[{m.mesh.name(), d.name}] = {m.mesh.size(), d.components};
    get().add_mesh(std::move(m));
  }

  void set_restart_writer(py::object writer) {
    if (!PyCallable_Check(writer.ptr()))
      throw mpi::UsageError(who_ + ": set_restart_writer() needs a callable that returns bytes");
    auto keep = std::make_shared<HeldObject>(std::move(writer));
    const std::string who = who_;
    get().set_restart_writer([keep, who] {
      py::gil_scoped_acquire gil;
      try {
        const py::bytes b = py::bytes(keep->object());
        const std::string s = b;
        return std::vector<char>(s.begin(), s.end());
      } catch (py::error_already_set& e) {
        throw Error(who + ": its restart writer raised " + std::string(e.what()));
      } catch (const py::cast_error&) {
        throw Error(who + ": its restart writer returned no bytes");
      }
    });
  }

  py::bytes restart_state() const {
    const std::vector<char>& s = get().restart_state();
    return py::bytes(s.data(), s.size());
  }

  void initialize() {
    mpi::ExternalParticipant& p = get();
    py::gil_scoped_release release;
    p.initialize();
  }

  void advance(double dt) {
    mpi::ExternalParticipant& p = get();
    py::gil_scoped_release release;
    p.advance(dt);
  }

  void finalize() {
    mpi::ExternalParticipant& p = get();
    py::gil_scoped_release release;
    p.finalize();
  }

  py::array read(const std::string& mesh, const std::string& data, py::object relative_time) {
    mpi::ExternalParticipant& p = get();
    if (relative_time.is_none())
      p.read(mesh, data, values_);
    else
      p.read(mesh, data, relative_time.cast<double>(), values_);
    const Eigen::Index n = values_.rows(), c = values_.cols();
    if (c == 1) {
      py::array_t<double> out(n);
      std::copy(values_.data(), values_.data() + n, out.mutable_data());
      return out;
    }
    py::array_t<double> out(std::vector<py::ssize_t>{n, c});
    auto o = out.mutable_unchecked<2>();
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < c; ++j) o(i, j) = values_(i, j);
    return out;
  }

  void write(const std::string& mesh, const std::string& data, py::handle values) {
    const auto it = shapes_.find({mesh, data});
    if (it == shapes_.end())  // the API's message names what was declared
      return get().write(mesh, data, Eigen::MatrixXd());
    const auto [rows, cols] = it->second;
    const std::string what = fmt::format("write('{}', '{}')", mesh, data);
    const auto a = py::array_t<double, py::array::forcecast>::ensure(values);
    if (!a) throw mpi::UsageError(fmt::format("{}: {} got no array of numbers", who_, what));
    const bool fits = (a.ndim() == 1 && a.shape(0) == rows && cols == 1) ||
                      (a.ndim() == 2 && a.shape(0) == rows && a.shape(1) == cols);
    if (!fits) {
      std::string shape;
      for (py::ssize_t d = 0; d < a.ndim(); ++d)
        shape += (d ? ", " : "") + std::to_string(a.shape(d));
      throw mpi::UsageError(
          fmt::format("{}: {} got an array of shape ({}), not ({}{})", who_, what, shape, rows,
                      cols == 1 ? std::string(",") : ", " + std::to_string(cols)));
    }
    Eigen::MatrixXd m(rows, cols);
    const double* d = a.data();
    const py::ssize_t s0 = a.strides(0) / py::ssize_t(sizeof(double));
    const py::ssize_t s1 = a.ndim() == 2 ? a.strides(1) / py::ssize_t(sizeof(double)) : 0;
    for (Eigen::Index i = 0; i < rows; ++i)
      for (Eigen::Index j = 0; j < cols; ++j) {
        const double v = d[i * s0 + j * s1];
        if (!std::isfinite(v))
          throw Error(
              fmt::format("{}: {} got {} at point {}{}: the program's state is no longer "
                          "physical",
                          who_, what, v, i, cols > 1 ? fmt::format(", component {}", j) : ""));
        m(i, j) = v;
      }
    get().write(mesh, data, m);
  }

 private:
  std::string who_;
  std::unique_ptr<mpi::ExternalParticipant> p_;
  std::map<std::pair<std::string, std::string>, std::pair<Eigen::Index, Eigen::Index>> shapes_;
  Eigen::MatrixXd values_;  // read()'s buffer, copied into each returned array
};

}  // namespace

void bind_external(py::module_& m) {
  m.attr("has_mpi") = true;
  // The API's own errors as partita.UsageError and partita.RunStopped (both partita.Error);
  // module.cpp's translator takes the others (registered before: asked after this one).
  py::register_exception_translator([](std::exception_ptr p) {
    const auto raise = [](const char* kind, const std::string& message) {
      py::object cls = py::module_::import("partita._errors").attr(kind);
      py::object error = cls(message);
      PyErr_SetObject(cls.ptr(), error.ptr());
    };
    try {
      if (p) std::rethrow_exception(p);
    } catch (const mpi::UsageError& e) {
      raise("UsageError", e.what());
    } catch (const mpi::RunStopped& e) {
      raise("RunStopped", e.what());
    }
  });
  py::class_<External>(m, "ExternalParticipant")
      .def(py::init<const std::string&, const std::string&, const std::vector<std::string>&,
                    py::object, double>(),
           py::arg("participant"), py::arg("case_file"), py::arg("overrides"),
           py::arg("fortran_comm"), py::arg("peer_timeout"))
      .def("close", &External::close)
      .def("add_mesh", &External::add_mesh, py::arg("mesh"))
      .def(
          "set_stable_time_step", [](External& e, double dt) { e.get().set_stable_time_step(dt); },
          py::arg("dt"))
      .def("set_restart_writer", &External::set_restart_writer, py::arg("writer"))
      .def("initialize", &External::initialize)
      .def("is_resuming", [](const External& e) { return e.get().is_resuming(); })
      .def("restart_state", &External::restart_state)
      .def("is_coupling_ongoing", [](const External& e) { return e.get().is_coupling_ongoing(); })
      .def("stopped_by_signal", [](const External& e) { return e.get().stopped_by_signal(); })
      .def("time_step_size", [](const External& e) { return e.get().time_step_size(); })
      .def("time", [](const External& e) { return e.get().time(); })
      .def("requires_writing_checkpoint",
           [](External& e) { return e.get().requires_writing_checkpoint(); })
      .def("requires_reading_checkpoint",
           [](External& e) { return e.get().requires_reading_checkpoint(); })
      .def("read", &External::read, py::arg("mesh"), py::arg("data"), py::arg("relative_read_time"))
      .def("write", &External::write, py::arg("mesh"), py::arg("data"), py::arg("values"))
      .def(
          "set_monitor",
          [](External& e, const std::string& name, double value, const std::string& unit) {
            e.get().set_monitor(name, unit, value);
          },
          py::arg("name"), py::arg("value"), py::arg("unit"))
      .def("advance", &External::advance, py::arg("dt"))
      .def("finalize", &External::finalize);
}

}  // namespace partita::python
