// The case file's schema: every key a case accepts, declared once (validation and `partita docs`).
#include "partita/run/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/explicit_scheme.hpp"
#include "partita/run/sweep.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

// ---------------------------------------------------------------------------------------------
// Schema

std::shared_ptr<const config::Spec> case_spec(const Registries& registries) {
  using config::Spec;
  auto time = std::make_shared<Spec>("time", "fixed time windows");
  time->real("window", "size of a coupling time window").unit("s").positive().required();
  time->real("end", "end time (the last window ends at or just after it)").unit("s").positive();
  time->integer("windows", "number of windows (instead of end)").min(1);
  time->one_of({"end", "windows"});

  auto exchange =
      std::make_shared<Spec>("exchange", "one data field sent from one mesh to another");
  exchange
      ->string("data",
               "name of the field (a write of the sender's mesh and a read of the receiver's)")
      .required();
  exchange->string("from", "sender as participant.mesh").required();
  exchange->string("to", "receiver as participant.mesh").required();
  exchange
      ->any("mapper",
            "a mapper name, or a map {type: name, <the mapper's own keys>} (partita docs NAME "
            "lists them; e.g. {type: rbf, support_radius: 2 mm}); known: " +
                join_names(registries.mappers.names()))
      .def("nearest-neighbor");
  exchange->choice("constraint",
                   "override the constraint that the data kind implies (intensive: consistent, "
                   "extensive: conservative)",
                   {"consistent", "conservative"});
  exchange
      ->choice("reader_sees",
               "what a subcycling reader sees at substep k/m: the newest value (constant) or "
               "linear interpolation between the window's start and end values",
               {"constant", "linear"})
      .def("linear");
  exchange
      ->choice("writer_combines",
               "how a subcycling writer's substep values make the window's value",
               {"average", "last"})
      .def("average");
  exchange
      ->choice("map_on",
               "which participant's process computes the mapping when participants run as "
               "processes of their own (--participant): receiver: the sender's values travel and "
               "the receiver maps them; sender: the values travel mapped to the receiver's mesh. "
               "Choose the side whose mesh is the smaller to travel. The numbers are the same "
               "either way (and in one process, where it changes nothing)",
               {"receiver", "sender"})
      .def("receiver");

  auto coupling = std::make_shared<Spec>("coupling", "how the participants advance together");
  coupling->string("scheme", "coupling scheme; known: " + join_names(registries.schemes.names()))
      .required();
  coupling->strings(
      "order",
      "participants in scheme order (default: file order); a serial scheme runs the first "
      "first");
  coupling->any("substeps",
                "per participant: a number of substeps per window (>= 1) or auto (from its "
                "stable time step); default 1");
  coupling->list("exchanges", "the exchanged fields", exchange).required();
  coupling->list("convergence",
                 "implicit schemes: measures, all must hold; each {type, data, limit}; known "
                 "types: " +
                     join_names(registries.convergence_measures.names()),
                 nullptr);
  coupling->any("acceleration",
                "implicit schemes: {type: name, <the acceleration's own keys>} (partita docs "
                "NAME lists them; e.g. {type: iqn-ils, initial_relaxation: 0.1}); known: " +
                    join_names(registries.accelerations.names()));
  coupling->integer("max_iterations", "implicit schemes: most iterations per window")
      .min(1)
      .def(100);
  coupling
      ->choice("on_max_iterations",
               "implicit schemes: at max_iterations stop with an error, or accept the "
               "window with a warning",
               {"error", "accept"})
      .def("accept");
  coupling
      ->boolean("concurrent",
                "parallel schemes (explicit-parallel, implicit-parallel): the participants of "
                "this process take each window at the same time, each on a thread of its own, "
                "sharing the --threads (2 participants, --threads 4: 2 OpenMP threads each); "
                "false: one after the other; the results are the same bits either way")
      .def(true);
  coupling
      ->real("balance_tolerance",
             "warn when an exchange's total (a force's sum, or a traction's or other field's "
             "integral over point weights) arrives after mapping off by more than this fraction "
             "of what was sent (audit columns in coupling.csv)")
      .positive()
      .def(0.01);
  coupling
      ->real("energy_tolerance",
             "energy audit: the largest share of the work that passed through an interface "
             "(both ways, since t = 0) that the coupling itself may create (the sum of the work "
             "done on both participants; zero for a lossless interface; columns in "
             "coupling.csv); acts when exceeded for 20 windows in a row")
      .positive()
      .def(0.5);
  coupling
      ->choice("on_energy_created",
               "energy audit beyond energy_tolerance: stop the run with a diagnosis, or warn once "
               "and count the windows",
               {"stop", "warn"})
      .def("stop");

  auto monitor =
      std::make_shared<Spec>("monitor", "a CSV time series DIR/<name>.csv of solver quantities");
  monitor->string("name", "file name without .csv").required();
  monitor->strings("quantities", "participant.quantity of each column").required();
  monitor
      ->integer("every_windows",
                "a row every this many windows (and the initial state and the last window): the "
                "participants are asked for the quantities only in windows where a monitor or "
                "the energy balance records, which saves the passes over particles and contacts "
                "that some quantities take (a DEM's elastic_energy, kinetic_energy); a "
                "non-finite value then stops the run at the next recorded window, up to this "
                "many windows late (the participants' own state checks still run every window)")
      .min(1)
      .max(1000000000)
      .def(1);
  auto monitor_plot = std::make_shared<Spec>(
      "monitor plot",
      "quantities of the monitor drawn against another of its quantities instead of time "
      "(e.g. {x: hull.bow.penetration, y: [hull.bow.force_z]}): DIR/<name>_vs_<x>.png");
  monitor_plot->string("x", "the quantity along the x axis, one of the monitor's quantities")
      .required();
  monitor_plot->strings("y", "the quantities drawn over it, of the monitor's quantities")
      .required();
  monitor->list("plots",
                "plots of the monitor's quantities against one of them, beside its plot over "
                "time; each {x, y}",
                monitor_plot);

  auto energy = std::make_shared<Spec>(
      "energy",
      "the energy balance of the whole coupled system, DIR/energy.csv at every window (or every "
      "energy.every_windows): the "
      "named monitor quantities (participant.quantity, in J) by role, their sums and `energy "
      "balance error [-]` = (stored + dissipated - inputs - initial) / scale, initial = the same "
      "sum at t = 0, scale = max(sum |inputs|, sum |stored| + sum |dissipated|, floor)");
  energy->strings("inputs",
                  "work put into the system (an indenter's work, an applied load's work, "
                  "gravity's work), e.g. [plate.indenter.work]");
  energy->strings("stored", "energy held (kinetic, elastic, potential)").required();
  energy->strings("dissipated",
                  "energy lost (plastic work, friction, damping, breakage, contact)");
  energy
      ->choice("coupling",
               "the net energy the coupling's interfaces created (the energy audit's pairs, "
               "column `coupling created`; a lossless coupling creates none): reported, so that "
               "it shows in the error, or counted as an input (the error then measures the "
               "participants' own balances only)",
               {"reported", "counted"})
      .def("reported");
  energy->real("tolerance", "bound on |energy balance error|: beyond it warn once, or stop")
      .positive();
  energy
      ->choice("on_exceeded", "beyond the tolerance: warn once and count the windows, or stop",
               {"warn", "stop"})
      .def("warn");
  energy
      ->real("floor",
             "smallest scale of the error (keeps round-off at rest from reading as an error); "
             "a window whose energy (sum |inputs| or sum |stored| + sum |dissipated|) stays "
             "below it is written to energy.csv but not held to the tolerance nor counted in the "
             "run's largest error; default none")
      .unit("J")
      .positive();
  energy
      ->integer("every_windows",
                "a row of energy.csv every this many windows (and the initial state and the last "
                "window); its terms are cumulative works and present energies, so a sampled "
                "balance misses nothing but the windows between (the largest error is read over "
                "the rows written)")
      .min(1)
      .max(1000000000)
      .def(1);

  auto output = std::make_shared<Spec>("output", "VTK output under DIR/vtk");
  output->real("every", "simulated time between frames (default: first and last frame only)")
      .unit("s")
      .positive();
  output->boolean("interface", "also write the interface meshes with their exchanged data (.vtp)")
      .def(true);
  auto restart = std::make_shared<Spec>(
      "restart",
      "restart files DIR/restart/w<window>.bin; continue with partita run CASE --resume DIR");
  restart->integer("every_windows", "windows between restart files").min(1);
  restart->real("every_minutes", "wall-clock minutes between restart files").positive();
  restart->integer("keep", "newest restart files kept (older ones are removed)").min(1).def(2);
  restart->boolean("at_end", "also write one after the last window (to extend the run later)")
      .def(true);
  output->section(
      "restart",
      "restart files (a run stopped by SIGINT/SIGTERM writes one whether declared or not)",
      restart);
  auto vtk_spec = std::make_shared<Spec>("vtk", "encoding of the VTK XML files (.vtu, .vtp)");
  vtk_spec
      ->choice("format",
               "zlib: appended binary, zlib-compressed (VTK's own default; the smallest files), "
               "binary: appended raw (the fastest to write), ascii: text (to read by eye)",
               vtk::format_names())
      .def("zlib");
  vtk_spec
      ->choice("precision",
               "of the solvers' point and cell fields (displacement, stress, velocity, force, "
               "...): float32 (7 significant digits, files 1.5x smaller) or float64 (the "
               "solver's values exactly); coordinates and ids are always written exactly",
               {"float32", "float64"})
      .def("float32");
  vtk_spec->integer("zlib_level", "zlib compression level: 1 fastest .. 9 smallest")
      .min(1)
      .max(9)
      .def(1);
  output->section("vtk", "VTK file format (every participant's files)", vtk_spec);
  output->strings("scripts",
                  "post-processing scripts of the case folder, run by `partita run` after the last "
                  "window with the output folder as argument (e.g. plots of the final state)");

  auto root = std::make_shared<Spec>("case", "a coupled simulation");
  root->string("case", "the case's name (output goes to out/<name> by default)").required();
  root->section("time", "time windows", time).required();
  root->any("participants",
            "map of participant name -> {solver: <registered solver>, solver keys...}; solvers: " +
                join_names(registries.solvers.names()) +
                "; or solver: external, a program with its own time loop that joins over MPI "
                "(partita::mpi::ExternalParticipant)")
      .required();
  root->section("coupling",
                "coupling scheme and exchanges (leave it out for a case of one participant: it "
                "then steps alone, as many steps per window as its stable time step needs)",
                coupling);
  root->list("monitors", "scalar time series", monitor);
  root->section("energy", "energy balance of the whole system (DIR/energy.csv)", energy);
  root->section("output", "VTK output", output);
  root->strings("plugins",
                "solver plugins (shared libraries built against this partita) that the case "
                "needs, loaded before it is read; paths relative to the case file; --plugin "
                "libraries load first, a library named twice loads once (README: As a plugin)");
  root->section("sweep",
                "a parametric sweep (partita run runs every variant; see partita docs case)",
                Sweep::spec());
  return root;
}

std::vector<CasePlugin> case_plugins(const std::filesystem::path& case_file,
                                     const std::vector<std::string>& overrides) {
  const config::Node root = config::Node::load_file(case_file, overrides);
  std::vector<CasePlugin> plugins;
  if (!root.is_map() || !root.has("plugins")) return plugins;
  const config::Node list = root["plugins"];
  if (!list.is_sequence())
    list.fail("expected a list of plugin libraries, e.g. [build/libmy_solver.so], found " +
              list.describe());
  const auto dir = std::filesystem::absolute(case_file).parent_path();
  for (const config::Node& item : list.items()) {
    if (!item.is_scalar() || item.as_string().empty())
      item.fail("expected the path of a plugin library, found " + item.describe());
    plugins.push_back({dir / item.as_string(), item});
  }
  return plugins;
}

}  // namespace partita::run
