// partita: the command line. A thin main over the libraries:
//   partita run CASE.yaml [--output DIR] [--threads N] [--log-level L] [--resume DIR] [--no-plots]
//   mpirun -n 1 partita run CASE --participant A : -n 1 partita run CASE --participant B
//   mpirun -n N partita run CASE           (a case of one DEM participant, on N ranks)
//   mpirun -n 1 partita run CASE --participant A : -n N partita run CASE --participant B
//                                          (B, a DEM, on N ranks beside A)
//   partita check CASE.yaml
//   partita list
//   partita docs [NAME]
// Every subcommand takes --plugin LIB (repeatable): a solver plugin (app/plugin_loader.hpp).
// Exit status 0 on success; 1 with one clear message on any user error; 2 on usage errors;
// 128 + N when signal N (SIGINT 130, SIGTERM 143) stopped a run (after a restart file).

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <atomic>
#include <csignal>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "after_run.hpp"
#include "distributed.hpp"
#include "partita/adapters/mesh_files.hpp"
#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/version.hpp"
#include "partita/run/case_run.hpp"
#include "plugin_loader.hpp"
#include "process.hpp"
#include "sweep_runner.hpp"

namespace {

using partita::coupling::Registries;

// SIGINT / SIGTERM: the run finishes its window, writes a restart file, flushes its CSV files and
// returns; a second signal of the same kind ends the process at once (SA_RESETHAND).
std::atomic<int> g_stop_signal{0};

extern "C" void on_stop_signal(int signal) {
  g_stop_signal.store(signal);
}

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

Registries make_registries() {
  Registries r;
  partita::coupling::register_builtin(r);
  partita::adapters::register_all(r);
  return r;
}

// Visit every registry with its heading.
template <class F>
void for_each_registry(const Registries& r, F&& f) {
  f("solvers", r.solvers);
  f("mappers", r.mappers);
  f("schemes", r.schemes);
  f("accelerations", r.accelerations);
  f("convergence measures", r.convergence_measures);
}

int list(const Registries& r) {
  for_each_registry(r, [](const char* heading, const auto& reg) {
    std::cout << heading << ":\n";
    std::size_t w = 0;
    for (const auto& e : reg.entries()) w = std::max(w, e.name.size());
    for (const auto& e : reg.entries())
      std::cout << "  " << e.name << std::string(w + 2 - e.name.size(), ' ') << e.doc << "\n";
  });
  return 0;
}

int docs(const Registries& r, const std::string& name) {
  if (name.empty() || name == "case") {
    std::cout << partita::run::case_spec(r)->docs() << "\n"
              << "After a run, partita run draws a PNG plot of each CSV file of the output "
                 "folder (python3 with matplotlib); partita run --no-plots, or the environment "
                 "variable PARTITA_NO_PLOTS=1, leaves them out (the CSV files and output.scripts "
                 "are not affected).\n"
              << "Each registered name has its own page: partita docs NAME (see partita list).\n";
    return 0;
  }
  bool found = false;
  std::vector<std::string> all;
  for_each_registry(r, [&](const char* heading, const auto& reg) {
    for (const auto& e : reg.entries()) {
      all.push_back(e.name);
      if (e.name != name) continue;
      found = true;
      std::cout << e.name << " (" << reg.kind() << "): " << e.doc << "\n";
      if (e.spec)
        std::cout << e.spec->docs(2);
      else
        std::cout << "  (no parameters)\n";
      if (!e.quantities.empty()) {
        std::cout << "  monitor quantities (for monitors: - {quantities: [participant.NAME]}):\n";
        std::size_t w = 0;
        for (const auto& q : e.quantities) w = std::max(w, q.name.size());
        for (const auto& q : e.quantities)
          std::cout << "    " << q.name << std::string(w + 2 - q.name.size(), ' ') << "["
                    << (q.unit.empty() ? "-" : q.unit) << "] " << q.doc << "\n";
      }
    }
  });
  if (!found)
    throw partita::Error("no documentation for '" + name +
                         "': it is not a registered name; known names: " +
                         partita::join_names(all) + partita::did_you_mean(name, all));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "partita: partitioned coupling of simulation codes (DEM granules and FEM structures first)"};
  app.set_version_flag("--version", std::string("partita ") + partita::version());
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "Log level: trace, debug, info, warn, error, critical, off")
      ->capture_default_str();

  std::string case_file, output_dir, doc_name;
  int threads = 0;
  auto* run =
      app.add_subcommand("run", "Run a case: partita run CASE.yaml [--output DIR] [--threads N]");
  run->add_option("case", case_file, "The case file (YAML)")->required();
  run->add_option("-o,--output", output_dir, "Output folder (default: out/<case name>/)");
  run->add_option("-t,--threads", threads, "Threads for the solvers (default: all cores)")
      ->check(CLI::PositiveNumber);
  run->add_option("--log-level", log_level,
                  "Log level: trace, debug, info, warn, error, critical, off");
  std::vector<std::string> overrides;
  std::string resume_dir;
  bool no_sweep = false;
  bool no_plots = false;
  int jobs = 1;
  run->add_flag("--no-sweep", no_sweep,
                "Run the case as written, ignoring its sweep section (each variant of a sweep "
                "runs so)");
  run->add_flag("--no-plots", no_plots,
                "Do not draw the PNG plots of the CSV files after the run (nor a sweep's "
                "sweep.png); the environment variable PARTITA_NO_PLOTS=1 does the same. The "
                "case's output.scripts still run");
  run->add_option("-j,--jobs", jobs, "Variants of a sweep run at once (default 1)")
      ->check(CLI::PositiveNumber);
  run->add_option("--resume", resume_dir,
                  "Continue the run whose output folder this is from its newest restart file "
                  "(DIR/restart/w<window>.bin), bit for bit; time and output may change with --set "
                  "(time.end raised, output.every), the participants, the coupling and the monitors may "
                  "not");
  std::string participant;
  double peer_timeout = 600.0;
  bool on_ranks = false;
  run->add_option("--participant", participant,
                  "Run only this participant, in this process, with the others in processes of "
                  "their own (under mpirun: mpirun -n 1 partita run CASE --participant A : -n 1 "
                  "partita run CASE --participant B; a DEM participant may have several: -n 3)");
  run->add_flag("--on-ranks", on_ranks,
                "With --participant: run the participant on its processes' ranks even where it "
                "has one (a DEM then steps its split bed, whose results are the same bytes on any "
                "number of processes; more than one process gives the ranks anyway)");
  run->add_option("--peer-timeout", peer_timeout,
                  "With --participant, or on several ranks: the longest wait for another "
                  "process's message [s] (default 600): a stuck process ends the run after it")
      ->check(CLI::PositiveNumber);
  run->add_option("--set", overrides,
                  "Change a value of the case: KEY.PATH=VALUE with map keys joined by dots and "
                  "list elements as key[i] (e.g. time.end=0.01, "
                  "participants.plate.loads[0].pressure='20 kPa'); repeatable")
      ->take_all();
  auto* check = app.add_subcommand(
      "check", "Validate a case completely without running it, or a mesh file (.stl, .msh)");
  check->add_option("case", case_file, "The case file (YAML), or a mesh file (.stl, Gmsh .msh)")
      ->required();
  check->add_option("--log-level", log_level, "Log level");
  check
      ->add_option("--set", overrides,
                   "Change a value of the case before checking it: KEY.PATH=VALUE (list elements "
                   "as key[i])")
      ->take_all();
  auto* lst = app.add_subcommand(
      "list", "List every registered solver, mapper, scheme, acceleration and convergence measure");
  auto* doc =
      app.add_subcommand("docs", "The parameter reference, generated from the declarations");
  doc->add_option("name", doc_name, "A registered name (see partita list), or 'case' (default)");
  std::vector<std::string> plugin_files;
  for (CLI::App* command : {&app, run, check, lst, doc})
    partita::app::add_plugin_option(*command, plugin_files);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    partita::log::set_level(partita::log::parse_level(log_level));
    Registries registries = make_registries();
    partita::app::Plugins plugins(registries);
    plugins.load_command_line(plugin_files);
    if (app.got_subcommand("list")) return list(registries);
    if (app.got_subcommand("docs")) return docs(registries, doc_name);

    partita::run::RunOptions options;
    options.output_dir = output_dir;
    options.overrides = overrides;
    options.resume_dir = resume_dir;
    options.stop_signal = &g_stop_signal;
#ifdef _OPENMP
    options.threads = threads > 0 ? threads : omp_get_num_procs();
    omp_set_num_threads(options.threads);
#else
    options.threads = threads > 0 ? threads : 1;
#endif
    if (app.got_subcommand("check")) {
      if (const auto mesh = partita::adapters::describe_mesh_file(case_file)) {
        std::cout << "partita check: " << *mesh << "\n";
        return 0;
      }
    }
    plugins.load_case(case_file, overrides);  // a case file from here on
    if (app.got_subcommand("check")) {
      options.check_only = true;
      partita::run::CaseRun c(case_file, registries, options);
      std::cout << "partita check: " << case_file << " is valid\n";
      for (const auto& name : c.external_participants())
        std::cout << "partita check: participant '" << name
                  << "' is an external program (solver: external): its meshes, fields and "
                     "quantities are checked when it joins the run (the handshake); the rest of "
                     "the case against the exchanges that name it\n";
      return 0;
    }
    const bool plots = partita::app::plots_wanted(no_plots);
    auto finish = [&](const std::filesystem::path& dir) {
      if (plots)
        partita::app::plot_csv_files(dir);
      else
        partita::log::get("app")->debug("plots: not drawn (--no-plots or PARTITA_NO_PLOTS)");
    };
    if (on_ranks && participant.empty())
      throw partita::Error(
          "--on-ranks gives a participant of a run of participants as processes its ranks "
          "(with --participant NAME); a case of one participant runs on the ranks of mpirun "
          "without it: mpirun -n N partita run CASE");
    if (!participant.empty()) {
      if (!no_sweep && resume_dir.empty() && partita::app::has_sweep(case_file, overrides))
        throw partita::Error(
            "--participant " + participant + ": " + case_file +
            " has a sweep section; a sweep runs its variants each in one process (run it "
            "without --participant), or give --no-sweep to run the case as written in processes");
      partita::app::DistributedOptions d;
      d.case_file = case_file;
      d.run = options;
      d.participant = participant;
      d.peer_timeout = peer_timeout;
      d.on_ranks = on_ranks;
      d.stop_signal = &g_stop_signal;
      d.install_stop_handlers = install_stop_handlers;
      d.on_finished = [&](const partita::run::CaseRun& c) {
        finish(c.output_dir());
        partita::app::run_scripts(c.scripts(), c.output_dir());
        std::cout << "partita run: finished; output in " << c.output_dir().string() << "/\n";
      };
      return partita::app::run_distributed(registries, d);
    }
    // mpirun -n N partita run CASE: a case of one participant on the N ranks
    if (partita::app::started_by_mpirun() &&
        (partita::app::distributed_available() || partita::app::started_with_others())) {
      if (!no_sweep && resume_dir.empty() && partita::app::has_sweep(case_file, overrides))
        throw partita::Error(
            case_file +
            " has a sweep section, and this process was started by mpirun: a sweep "
            "runs its variants each in a process of its own (run it without mpirun), or give "
            "--no-sweep to run the case as written on the ranks");
      partita::app::RanksOptions r;
      r.case_file = case_file;
      r.run = options;
      r.peer_timeout = peer_timeout;
      r.install_stop_handlers = install_stop_handlers;
      r.stop_signal = &g_stop_signal;
      r.on_finished = [&](const partita::run::CaseRun& c) {
        finish(c.output_dir());
        partita::app::run_scripts(c.scripts(), c.output_dir());
        std::cout << "partita run: finished; output in " << c.output_dir().string() << "/\n";
      };
      return partita::app::run_on_ranks(registries, r);
    }
    if (!no_sweep && resume_dir.empty() && partita::app::has_sweep(case_file, overrides)) {
      install_stop_handlers();
      partita::app::SweepOptions so;
      so.case_file = case_file;
      so.output_dir = output_dir;
      so.overrides = overrides;
      so.jobs = jobs;
      so.plots = plots;
      so.threads = options.threads;
      so.log_level = log_level;
      so.stop_signal = &g_stop_signal;
      so.plugins = plugins.command_line();
      return partita::app::run_sweep(registries, so);
    }
    partita::run::CaseRun c(case_file, registries, options);
    install_stop_handlers();
    c.run();
    finish(c.output_dir());
    if (const int signal = c.summary().stopped_by_signal; signal != 0) {
      std::cout << "partita run: stopped by signal " << signal << " after window "
                << c.summary().windows << "; output in " << c.output_dir().string() << "/";
      if (!c.summary().last_restart.empty()) {
        std::cout << "; continue with: partita run " << case_file << " --resume "
                  << c.output_dir().string();
        for (const auto& p : plugins.command_line()) std::cout << " --plugin " << p;
      }
      std::cout << "\n";
      return 128 + signal;
    }
    partita::app::run_scripts(c.scripts(), c.output_dir());
    // name only what is there: a case may write no VTK (no output.vtk, or no participant with
    // a mesh to show)
    bool vtk = false;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(c.output_dir() / "vtk", ec))
      if (entry.path().extension() == ".pvd") vtk = true;
    std::cout << "partita run: finished; output in " << c.output_dir().string()
              << "/ (CSV time series" << (plots ? " and their PNG plots" : "")
              << (vtk ? "; VTK series for ParaView in vtk/*.pvd" : "") << ")\n";
    return 0;
  } catch (const partita::Error& e) {
    std::cerr << "partita: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "partita: error: out of memory: the case needs more memory than this machine "
                 "gives the process (fewer particles or elements, or a machine with more "
                 "memory)\n";
    return 1;
  } catch (const std::exception& e) {
    // A condition partita does not check for yet: no library text reaches the user (it names
    // internals, not the input); the detail goes to the log for the bug report.
    partita::log::get("app")->debug("unexpected exception: {}", e.what());
    std::cerr << "partita: internal error: the run stopped on a condition that partita does not "
                 "check for yet; this is a bug, please report it with the case file and the "
                 "output of the same command with --log-level debug\n";
    return 1;
  }
}
