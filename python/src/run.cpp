// _partita.run and _partita.sweep: the run library's CaseRun (and the executable's sweep runner,
// app/sweep_runner.hpp) on a worker thread, while the calling thread waits with the GIL
// released, wakes every `poll` seconds to let Python handle its signals and to call the progress
// callback. A KeyboardInterrupt (Ctrl-C) or an exception of the callback asks the run to stop
// as SIGINT does for the executable: the window ends, a restart file is written, every CSV file
// is flushed; the exception is handed back with the summary (the package raises it). A second
// Ctrl-C meanwhile ends the process, as the executable's second SIGINT does.
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/stl.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "after_run.hpp"
#include "module.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/case_run.hpp"
#include "sweep_runner.hpp"

namespace py = pybind11;

namespace partita::python {

namespace {

namespace fs = std::filesystem;

// The progress the worker publishes after each window (read by the waiting thread).
struct Progress {
  std::atomic<std::int64_t> window{0}, windows{0};
  std::atomic<double> time{0.0};
  std::atomic<int> iterations{0};
};

int thread_count(int threads) {
  if (threads < 0) throw Error("threads=" + std::to_string(threads) + ": give 1 or more (0: all cores)");
#ifdef _OPENMP
  return threads > 0 ? threads : omp_get_num_procs();
#else
  return threads > 0 ? threads : 1;
#endif
}

// Run `work` on a worker thread; wait for it here, handling Python's signals and calling
// `on_poll` between waits. Returns the exception Python raised meanwhile (a KeyboardInterrupt,
// or one of on_poll), or None; rethrows the worker's exception.
py::object wait_for_worker(const std::function<void()>& work, std::atomic<int>& stop,
                           double poll, const std::function<void()>& on_poll) {
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_all();
  });
  py::object raised = py::none();
  bool interrupted = false;  // a KeyboardInterrupt came
  const auto wait = std::chrono::duration<double>(poll > 0.0 ? poll : 0.1);
  for (;;) {
    bool finished = false;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(m);
      finished = cv.wait_for(lock, wait, [&] { return done; });
    }
    if (finished) break;
    bool failed = PyErr_CheckSignals() != 0;
    if (!failed && raised.is_none() && on_poll) {
      try {
        on_poll();
      } catch (py::error_already_set& e) {
        e.restore();
        failed = true;
      }
    }
    if (failed) {
      // A second Ctrl-C while the run stops after its window ends the process at once, as the
      // executable's second SIGINT does (its handler is reset after the first, SA_RESETHAND):
      // the run cannot be left half-way in this process. Other exceptions wait for the window.
      const bool interrupt = PyErr_ExceptionMatches(PyExc_KeyboardInterrupt) != 0;
      if (interrupt && interrupted) {
        std::signal(SIGINT, SIG_DFL);
        std::raise(SIGINT);
      }
      interrupted = interrupted || interrupt;
      // the first exception stops the run
      PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
      PyErr_Fetch(&type, &value, &trace);
      PyErr_NormalizeException(&type, &value, &trace);
      if (value != nullptr && trace != nullptr) PyException_SetTraceback(value, trace);
      if (raised.is_none() && value != nullptr) raised = py::reinterpret_borrow<py::object>(value);
      Py_XDECREF(type);
      Py_XDECREF(value);
      Py_XDECREF(trace);
      stop.store(SIGINT);
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (failure) std::rethrow_exception(failure);
  return raised;
}

py::dict summary_dict(const run::RunSummary& s) {
  py::dict d;
  d["windows"] = s.windows;
  d["iterations"] = s.iterations;
  d["unconverged_windows"] = s.unconverged_windows;
  d["max_window_iterations"] = s.max_window_iterations;
  d["wall_seconds"] = s.wall_seconds;
  py::dict parts;
  for (const auto& [name, seconds] : s.participant_seconds) parts[py::str(name)] = seconds;
  d["participant_seconds"] = parts;
  d["mapping_seconds"] = s.mapping_seconds;
  d["output_seconds"] = s.output_seconds;
  d["overlap_seconds"] = s.overlap_seconds;
  d["core_seconds"] = s.core_seconds;
  d["resumed_from"] = s.resumed_from;
  d["stopped_by_signal"] = s.stopped_by_signal;
  d["last_restart"] = s.last_restart.string();
  d["imbalance_warnings"] = s.imbalance_warnings;
  d["energy_warnings"] = s.energy_warnings;
  d["energy_balance_warnings"] = s.energy_balance_warnings;
  return d;
}

py::dict run_case(const std::string& case_file, const std::string& output, int threads,
                  const std::vector<std::string>& overrides, const std::string& resume,
                  bool no_plots, const py::object& progress, double poll) {
  refuse_plugins(case_file, overrides);
  std::atomic<int> stop{0};
  Progress now;
  run::RunOptions options;
  options.output_dir = output;
  options.overrides = overrides;
  options.override_origins = override_origins(overrides, "run");
  options.resume_dir = resume;
  options.stop_signal = &stop;
  options.threads = thread_count(threads);
  options.on_window = [&now](std::int64_t done, std::int64_t windows, double time, int iterations) {
    now.windows = windows;
    now.time = time;
    now.iterations = iterations;
    now.window = done;  // last: the waiting thread reads the others once it sees this change
  };
  const bool plots = app::plots_wanted(no_plots);
  run::RunSummary summary;
  fs::path output_dir;
  std::int64_t reported = -1;
  const auto regs = registries();
  auto work = [&] {
#ifdef _OPENMP
    omp_set_num_threads(options.threads);  // this thread's OpenMP teams (as the executable's main)
#endif
    run::CaseRun c(case_file, *regs, options);
    now.windows = c.window_count();
    output_dir = c.output_dir();
    c.run();
    summary = c.summary();
    now.window = summary.windows;
    if (plots) app::plot_csv_files(c.output_dir());
    if (summary.stopped_by_signal == 0) app::run_scripts(c.scripts(), c.output_dir());
  };
  auto on_poll = [&] {
    if (progress.is_none()) return;
    const std::int64_t w = now.window.load();
    if (w == reported) return;
    reported = w;
    progress(w, now.windows.load(), now.time.load(), now.iterations.load());
  };
  py::object raised = wait_for_worker(work, stop, poll, on_poll);
  if (!progress.is_none() && raised.is_none() && reported != now.window.load())
    progress(now.window.load(), now.windows.load(), now.time.load(), now.iterations.load());
  py::dict out;
  out["output_dir"] = output_dir.string();
  out["summary"] = summary_dict(summary);
  out["exception"] = raised;
  return out;
}

py::dict sweep_case(const std::string& case_file, const std::string& output, int jobs,
                    int threads, const std::vector<std::string>& overrides, bool no_plots,
                    const std::string& executable, const std::string& log_level, double poll) {
  refuse_plugins(case_file, overrides);
  refuse_python_solvers(case_file, overrides);
  if (jobs < 1) throw Error("jobs=" + std::to_string(jobs) + ": give 1 or more");
  if (!fs::exists(executable))
    throw Error("the partita executable that runs a sweep's variants is not at '" + executable +
                "' (build it, or set PARTITA_EXECUTABLE to its path)");
  std::atomic<int> stop{0};
  app::SweepOptions so;
  so.case_file = case_file;
  so.output_dir = output;
  so.overrides = overrides;
  // where a value was given, for a CaseError's file: partita.sweep(over=...) for the swept
  // values (package: "sweep.parameters=..."), results=..., or set={'key': ...}
  so.override_origins = override_origins(overrides, "sweep");
  for (std::size_t i = 0; i < overrides.size(); ++i)
    for (const char* arg : {"parameters", "results"})
      if (overrides[i].rfind(std::string("sweep.") + arg + "=", 0) == 0)
        so.override_origins[i].file =
            std::string("partita.sweep(") + (arg[0] == 'p' ? "over" : "results") + "=...)";
  so.jobs = jobs;
  so.threads = thread_count(threads);
  so.plots = app::plots_wanted(no_plots);
  so.log_level = log_level;
  so.stop_signal = &stop;
  so.executable = executable;
  const fs::path dir =
      !so.output_dir.empty()
          ? so.output_dir
          : fs::current_path() / "out" / config::Node::load_file(case_file, overrides).string("case");
  so.output_dir = dir;
  int status = 0;
  const auto regs = registries();
  auto work = [&] { status = app::run_sweep(*regs, so); };
  py::object raised = wait_for_worker(work, stop, poll, {});
  py::dict out;
  out["status"] = status;
  out["output_dir"] = dir.string();
  out["exception"] = raised;
  return out;
}

}  // namespace

void bind_run(py::module_& m) {
  m.def("run", &run_case, py::arg("case_file"), py::arg("output"), py::arg("threads"),
        py::arg("overrides"), py::arg("resume"), py::arg("no_plots"), py::arg("progress"),
        py::arg("poll"));
  m.def("sweep", &sweep_case, py::arg("case_file"), py::arg("output"), py::arg("jobs"),
        py::arg("threads"), py::arg("overrides"), py::arg("no_plots"), py::arg("executable"),
        py::arg("log_level"), py::arg("poll"));
}

}  // namespace partita::python
