#include "partita/coupling/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/progress_line.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/coupling/sweep.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::coupling {

// The energy audit acts when the coupling has created more than the tolerated share of the work
// that passed for this many windows in a row: the lag of the explicit schemes makes single
// windows exceed it when a contact starts (the granules landing on an FE floor, a plate reaching
// the granules: 1-2 windows at up to 100 %, of 1e-14..1e-8 J), while an unstable coupling keeps
// creating energy (the undamped rubber plate: 0.66 at window 300, 0.92-0.97 from 500 on). The
// stable seed-000 cases stay below 0.2 (0.08-0.2 over the first 10 windows, < 0.02 after 100).
constexpr int kEnergyAuditWindows = 20;

namespace fs = std::filesystem;

namespace {
// Above this many windows a run is almost surely a typing error in time.window or time.end.
constexpr double kWindowWarning = 1e8;
}  // namespace

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
                join_names(registries.solvers.names()))
      .required();
  root->section("coupling",
                "coupling scheme and exchanges (leave it out for a case of one participant: it "
                "then steps alone, as many steps per window as its stable time step needs)",
                coupling);
  root->list("monitors", "scalar time series", monitor);
  root->section("output", "VTK output", output);
  root->section("sweep",
                "a parametric sweep (partita run runs every variant; see partita docs case)",
                Sweep::spec());
  return root;
}

// ---------------------------------------------------------------------------------------------
// Building

namespace {

std::pair<std::string, std::string> split_dot(const config::Node& n, const char* what) {
  const std::string s = n.as_string();
  const auto dot = s.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == s.size())
    n.fail(std::string("expected ") + what + " written participant." +
           (std::string(what) == "a quantity" ? "quantity" : "mesh") + ", found '" + s + "'");
  return {s.substr(0, dot), s.substr(dot + 1)};
}

// What a restart file must come from: the same participants and coupling (the time and output
// sections may change, e.g. a later end time). FNV-1a of their YAML text.
std::uint64_t case_identity(const config::Node& root) {
  std::string text = root.string("case");
  for (const char* key : {"participants", "coupling"}) {
    YAML::Emitter e;
    e << root[key].yaml();
    text += std::string("\n") + key + ":\n" + e.c_str();
  }
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

// A case name becomes a folder name (out/<case>/) and part of file names: a plain name only.
}  // namespace

Participant* CaseRun::participant(const std::string& name) const {
  for (const auto& p : participants_)
    if (p->name() == name) return p.get();
  return nullptr;
}

CaseRun::CaseRun(const fs::path& case_file, const Registries& registries, RunOptions options)
    : registries_(registries), options_(std::move(options)) {
  const config::Node root =
      config::Node::load_file(case_file, options_.overrides, options_.override_origins)
          .validated(case_spec(registries));
  name_ = root.string("case");
  check_plain_name(root["case"], name_, "the case name");
  case_dir_ = fs::absolute(case_file).parent_path();
  output_dir_ =
      options_.output_dir.empty() ? fs::current_path() / "out" / name_ : options_.output_dir;
  if (!options_.resume_dir.empty()) {
    if (!options_.output_dir.empty() &&
        fs::weakly_canonical(options_.output_dir) != fs::weakly_canonical(options_.resume_dir))
      throw Error("--resume " + options_.resume_dir.string() +
                  " continues in that folder; leave out --output (" + options_.output_dir.string() +
                  ")");
    output_dir_ = options_.resume_dir;
  }
  identity_ = case_identity(root);

  const config::Node time = root["time"];
  window_size_ = time.real("window");
  if (time.has("windows")) {
    window_count_ = time.integer("windows");
  } else {
    try {
      window_count_ = TimeWindow::count_to(time.real("end"), window_size_);
    } catch (const Error& e) {
      time["end"].fail(e.what());
    }
    if (window_size_ > time.real("end"))
      log::get("coupling")
          ->warn(
              "{}: time.window ({:.6g} s) is longer than time.end ({:.6g} s): the run makes one "
              "window "
              "and ends at t = {:.6g} s",
              time["window"].location().str(), window_size_, time.real("end"), window_size_);
  }
  if (static_cast<double>(window_count_) > kWindowWarning)
    log::get("coupling")
        ->warn(
            "{}: {} windows of {:.6g} s is more than {:.0e}: at a microsecond per window that is "
            "over "
            "a day of run time; check time.window and time.end",
            time.location().str(), window_count_, window_size_, kWindowWarning);
  if (root.has("output") && root["output"].has("every"))
    output_every_ = root["output"].real("every");
  if (root.has("output") && root["output"].has("restart")) {
    const config::Node r = root["output"]["restart"];
    if (r.has("every_windows")) restart_every_windows_ = r.integer("every_windows");
    if (r.has("every_minutes")) restart_every_seconds_ = 60.0 * r.real("every_minutes");
    restart_keep_ = static_cast<int>(r.integer("keep"));
    restart_at_end_ = r.boolean("at_end");
  }
  if (root.has("output") && root["output"].has("vtk")) {
    const config::Node v = root["output"]["vtk"];
    vtk_options_.format = vtk::parse_format(v.string("format"));
    vtk_options_.zlib_level = static_cast<int>(v.integer("zlib_level"));
    vtk_options_.precision = vtk::parse_precision(v.string("precision"));
  }
  if (root.has("output") && root["output"].has("scripts"))
    for (const config::Node& sn : root["output"]["scripts"].items()) {
      const fs::path script = case_dir_ / sn.as_string();
      if (!fs::exists(script))
        sn.fail("post-processing script '" + script.string() + "' does not exist");
      scripts_.push_back(script);
    }

  build_participants(root);
  const config::Node coupling = root["coupling"];
  if (root.has("coupling")) {
    build_exchanges(coupling);
    SchemeContext ctx;
    ctx.config = coupling;
    ctx.registries = &registries_;
    for (auto& p : participants_) ctx.participants.push_back(p.get());
    for (auto& e : exchanges_) ctx.exchanges.push_back(e.get());
    const auto& entry = registries_.schemes.get(coupling["scheme"]);
    scheme_ = entry.factory(ctx);
  } else {
    // A single-solver case: the participant steps through the windows alone (no exchanges).
    scheme_ = std::make_unique<ExplicitScheme>(std::vector<Participant*>{participants_[0].get()},
                                               std::vector<Exchange*>{}, true);
  }

  build_monitors(root);
  if (root.has("sweep")) {
    const Sweep sweep(root);  // validates the swept keys, labels, results and plot
    if (options_.check_only && options_.check_sweep_values) check_sweep_values(case_file, sweep);
  }

  if (root.has("output") && root["output"].has("restart") && !restart_blocker().empty())
    root["output"]["restart"].fail(restart_blocker() + "; remove output.restart");
  if (root.has("coupling")) {
    balance_tolerance_ = coupling.real("balance_tolerance");
    energy_tolerance_ = coupling.real("energy_tolerance");
    energy_stop_ = coupling.string("on_energy_created") == "stop";
  }
  for (const auto& e : exchanges_) {
    const bool extensive = e->spec().kind == DataKind::extensive;
    const bool weighted = e->from().find_mesh(e->from_mesh())->mesh.has_weights() &&
                          e->to().find_mesh(e->to_mesh())->mesh.has_weights();
    if (extensive || weighted) audited_.push_back(e.get());
  }
  // Energy audit: pairs of participants with exchanges both ways whose solvers report the work
  // done on them through the meshes they read on.
  for (const auto& e : exchanges_) {
    Participant* reader = &e->to();
    Participant* writer = &e->from();
    if (reader == writer || !reader->interface_work(e->to_mesh())) continue;
    auto it = std::find_if(energy_pairs_.begin(), energy_pairs_.end(), [&](const EnergyPair& p) {
      return (p.a == reader && p.b == writer) || (p.a == writer && p.b == reader);
    });
    if (it == energy_pairs_.end()) {
      energy_pairs_.push_back({reader->name() + "-" + writer->name(), reader, writer, {}, {}});
      it = std::prev(energy_pairs_.end());
    }
    auto& meshes = it->a == reader ? it->a_meshes : it->b_meshes;
    if (std::find(meshes.begin(), meshes.end(), e->to_mesh()) == meshes.end())
      meshes.push_back(e->to_mesh());
  }
  std::erase_if(energy_pairs_,
                [](const EnergyPair& p) { return p.a_meshes.empty() || p.b_meshes.empty(); });
}

CaseRun::~CaseRun() = default;

// Each swept value is checked where it will be used: the case is built (check only) with that
// one value set, as the variant will run it; an error names the value's line in the sweep list.
// One build per value, not per combination (a value valid alone is assumed valid with the
// others: keys that depend on each other are checked when the variant runs).
void CaseRun::check_sweep_values(const fs::path& case_file, const Sweep& sweep) const {
  for (const Sweep::Parameter& par : sweep.parameters())
    for (std::size_t i = 0; i < par.values.size(); ++i) {
      RunOptions o = options_;
      o.check_sweep_values = false;
      o.override_origins.resize(o.overrides.size());
      o.overrides.push_back(par.key + "=" + par.values[i]);
      o.override_origins.push_back(par.origins[i]);
      try {
        CaseRun variant(case_file, registries_, o);
      } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (the swept value " + par.values[i] + " of " +
                    par.key + ", as its variants will run it)");
      }
    }
}

void CaseRun::build_participants(const config::Node& root) {
  const config::Node ps = root["participants"];
  if (!ps.is_map() || ps.size() == 0)
    ps.fail(
        "expected a map of participants, e.g. participants: {fluid: {solver: tube1d-fluid}}; "
        "found " +
        ps.describe());
  std::vector<std::string> names = ps.keys();
  // scheme order
  const config::Node coupling = root["coupling"];
  std::vector<std::string> order = names;
  if (coupling.has("order")) {
    order = coupling.strings("order");
    const config::Node on = coupling["order"];
    std::set<std::string> seen;
    for (std::size_t i = 0; i < order.size(); ++i) {
      const config::Node item = on.is_sequence() ? on[i] : on;
      if (std::find(names.begin(), names.end(), order[i]) == names.end())
        item.fail("unknown participant '" + order[i] + "'; participants: " + join_names(names) +
                  did_you_mean(order[i], names));
      if (!seen.insert(order[i]).second)
        item.fail("participant '" + order[i] + "' appears twice in the order");
    }
    if (order.size() != names.size()) {
      std::vector<std::string> missing;
      for (const auto& n : names)
        if (!seen.count(n)) missing.push_back(n);
      on.fail("the order must list every participant once; missing: " + join_names(missing));
    }
  }
  const bool coupled = root.has("coupling");
  if (coupled && names.size() < 2)
    ps.fail("a coupled case needs at least 2 participants, found " + std::to_string(names.size()) +
            " (a single-solver case has no coupling section)");
  if (!coupled && names.size() != 1)
    ps.fail("a case with " + std::to_string(names.size()) +
            " participants needs a coupling section (scheme and exchanges); only a case with one "
            "participant runs without one");

  // substeps
  std::map<std::string, Substeps> substeps;
  if (coupling.has("substeps")) {
    const config::Node sn = coupling["substeps"];
    if (!sn.is_map())
      sn.fail("expected a map participant -> number of substeps or auto, found " + sn.describe());
    for (const std::string& k : sn.keys()) {
      const config::Node v = sn[k];
      if (std::find(names.begin(), names.end(), k) == names.end())
        v.fail("unknown participant '" + k + "'; participants: " + join_names(names) +
               did_you_mean(k, names));
      Substeps s;
      if (v.is_scalar() && v.as_string() == "auto") {
        s.automatic = true;
      } else {
        if (!v.is_scalar())
          v.fail("expected a number of substeps (>= 1) or auto, found " + v.describe());
        std::string text = v.as_string();
        long n = 0;
        try {
          n = v.as_integer();
        } catch (const Error&) {
          v.fail("expected a whole number of substeps (>= 1) or auto, found '" + text + "'" +
                 did_you_mean(text, {"auto"}));
        }
        if (n < 1) v.fail("substeps must be >= 1 (or auto), found " + std::to_string(n));
        s.count = static_cast<int>(n);
      }
      substeps[k] = s;
    }
  }

  struct Built {
    std::string name;
    config::Node node;
    std::string solver_name;
    std::unique_ptr<Solver> solver;
  };
  std::vector<Built> built;
  for (const std::string& name : order) {
    const config::Node pn = ps[name];
    if (name.find('.') != std::string::npos)
      pn.fail("a participant name may not contain '.', found '" + name +
              "' (meshes are named participant.mesh)");
    check_plain_name(pn, name, "a participant name");
    if (!pn.is_map() || !pn.has("solver"))
      pn.fail("participant '" + name + "' needs 'solver: <name>'; known solvers: " +
              join_names(registries_.solvers.names()));
    const auto& entry = registries_.solvers.get(pn["solver"]);
    config::Node validated = pn;
    if (entry.spec) {
      auto spec = std::make_shared<config::Spec>(*entry.spec);
      if (!spec->find("solver")) spec->string("solver", "the registered solver's name").required();
      validated = pn.validated(spec);
    }
    SolverContext ctx{name, validated, case_dir_, output_dir_, options_.threads};
    log::get("coupling")->debug("setting up participant '{}' ({})", name, entry.name);
    Stopwatch setup;
    std::unique_ptr<Solver> solver = entry.factory(ctx);
    if (setup.seconds() > 1.0)
      log::get("coupling")
          ->info("set-up of participant '{}' ({}): {:.1f} s", name, entry.name, setup.seconds());
    if (!solver) pn.fail("solver '" + entry.name + "' could not be built");
    built.push_back(Built{name, pn, entry.name, std::move(solver)});
  }

  // Surfaces handed from one participant to another (an FE face as a DEM wall): once every
  // participant is built, before anyone's meshes() is used for the exchanges.
  for (auto& b : built)
    for (const MeshRequest& req : b.solver->mesh_requests()) {
      const auto dot = req.source.find('.');
      const std::string pname = req.source.substr(0, dot);
      const std::string mname = dot == std::string::npos ? "" : req.source.substr(dot + 1);
      const Built* from = nullptr;
      for (const auto& other : built)
        if (other.name == pname) from = &other;
      if (dot == std::string::npos || !from)
        req.where.fail("'" + req.source + "' names no participant's mesh (participant.mesh); " +
                       "participants: " + join_names(names) + did_you_mean(pname, names));
      if (from == &b) req.where.fail("a participant cannot take a mesh from itself");
      std::vector<std::string> known;
      const InterfaceMesh* found = nullptr;
      for (const auto& m : from->solver->meshes()) {
        known.push_back(m.mesh.name());
        if (m.mesh.name() == mname) found = &m;
      }
      if (!found)
        req.where.fail("participant '" + pname + "' has no mesh '" + mname +
                       "'; its meshes: " + join_names(known) + did_you_mean(mname, known));
      if (found->mesh.num_triangles() == 0)
        req.where.fail("mesh '" + req.source +
                       "' has no triangles (a point set): a surface is needed");
      b.solver->receive_mesh(req.name, found->mesh);
    }

  for (auto& b : built) {
    const std::string& name = b.name;
    const config::Node& pn = b.node;
    Substeps s = substeps.count(name) ? substeps[name] : Substeps{};
    if (!coupled) s.automatic = true;  // alone: as many steps per window as its stability needs
    // A fixed number of substeps must not exceed the solver's stable time step.
    const double stable = b.solver->stable_time_step();
    if (!s.automatic && TimeWindow::longer_than(window_size_ / s.count, stable)) {
      const config::Node where = substeps.count(name) ? coupling["substeps"][name] : pn;
      where.fail(fmt::format(
          "participant '{}' would step {:.4g} s (window {:.4g} s / {} substeps), above its stable "
          "time step {:.4g} s; use substeps: {{{}: {}}} or more, or {{{}: auto}}",
          name, window_size_ / s.count, window_size_, s.count, stable, name,
          TimeWindow::substeps_for(window_size_, stable), name));
    }
    participants_.push_back(std::make_unique<LocalParticipant>(name, std::move(b.solver), s));
    if (coupled && participants_.back()->meshes().empty())
      pn.fail("solver '" + b.solver_name + "' of participant '" + name +
              "' exposes no coupling mesh");
    for (const auto& m : participants_.back()->meshes())
      check_plain_name(pn, m.mesh.name(),
                       "the mesh name '" + m.mesh.name() + "' of '" + name + "'");
  }
}

void CaseRun::build_exchanges(const config::Node& coupling) {
  std::vector<std::string> names;
  for (const auto& p : participants_) names.push_back(p->name());
  const std::vector<config::Node> items = coupling["exchanges"].items();
  if (items.empty()) coupling["exchanges"].fail("a coupled case needs at least one exchange");

  struct Resolved {
    Participant* p;
    const InterfaceMesh* mesh;
  };
  auto resolve = [&](const config::Node& n) {
    const auto [pname, mname] = split_dot(n, "a mesh");
    Participant* p = participant(pname);
    if (!p)
      n.fail("unknown participant '" + pname + "'; participants: " + join_names(names) +
             did_you_mean(pname, names));
    std::vector<std::string> meshes;
    for (const auto& m : p->meshes()) meshes.push_back(m.mesh.name());
    const InterfaceMesh* m = p->find_mesh(mname);
    if (!m)
      n.fail("participant '" + pname + "' has no mesh '" + mname +
             "'; its meshes: " + join_names(meshes) + did_you_mean(mname, meshes));
    return Resolved{p, m};
  };
  auto names_of = [](const std::vector<DataSpec>& v) {
    std::vector<std::string> n;
    for (const auto& d : v) n.push_back(d.name);
    return n;
  };

  for (const config::Node& item : items) {
    const std::string data = item.string("data");
    const Resolved from = resolve(item["from"]);
    const Resolved to = resolve(item["to"]);
    if (from.p == to.p) item["to"].fail("an exchange goes between two different participants");
    const DataSpec* ws = nullptr;
    for (const auto& d : from.mesh->writes)
      if (d.name == data) ws = &d;
    if (!ws) {
      const auto w = names_of(from.mesh->writes);
      item["data"].fail("participant '" + from.p->name() + "' does not write '" + data +
                        "' on mesh '" + from.mesh->mesh.name() + "'; it writes: " +
                        (w.empty() ? "nothing" : join_names(w)) + did_you_mean(data, w));
    }
    const DataSpec* rs = nullptr;
    for (const auto& d : to.mesh->reads)
      if (d.name == data) rs = &d;
    if (!rs) {
      const auto r = names_of(to.mesh->reads);
      item["data"].fail("participant '" + to.p->name() + "' does not read '" + data +
                        "' on mesh '" + to.mesh->mesh.name() + "'; it reads: " +
                        (r.empty() ? "nothing" : join_names(r)) + did_you_mean(data, r));
    }
    if (ws->components != rs->components)
      item["data"].fail("'" + data + "' has " + std::to_string(ws->components) +
                        " components where '" + from.p->name() + "' writes it but " +
                        std::to_string(rs->components) + " where '" + to.p->name() + "' reads it");
    for (const auto& e : exchanges_)
      if (&e->to() == to.p && e->to_mesh() == to.mesh->mesh.name() && e->data() == data)
        item.fail("'" + data + "' on " + to.p->name() + "." + to.mesh->mesh.name() +
                  " already has a sender (" + e->label() + ")");
    Constraint constraint =
        ws->kind == DataKind::extensive ? Constraint::conservative : Constraint::consistent;
    if (item.has("constraint"))
      constraint = item.string("constraint") == "conservative" ? Constraint::conservative
                                                               : Constraint::consistent;
    std::unique_ptr<Mapper> mapper =
        create_mapper(registries_.mappers, MapperContext{item["mapper"], constraint});
    Stopwatch setup;
    mapper->compute(from.mesh->mesh, to.mesh->mesh);
    if (setup.seconds() > 1.0)
      log::get("coupling")
          ->info("set-up of the mapping of '{}' {}.{} -> {}.{}: {:.1f} s", data, from.p->name(),
                 from.mesh->mesh.name(), to.p->name(), to.mesh->mesh.name(), setup.seconds());
    const ReaderSees rsee =
        item.string("reader_sees") == "constant" ? ReaderSees::constant : ReaderSees::linear;
    const WriterCombines wc =
        item.string("writer_combines") == "last" ? WriterCombines::last : WriterCombines::average;
    exchanges_.push_back(std::make_unique<Exchange>(
        data, Exchange::End{from.p, from.mesh->mesh.name()},
        Exchange::End{to.p, to.mesh->mesh.name()}, *ws, std::move(mapper), rsee, wc));
  }
}

void CaseRun::build_monitors(const config::Node& root) {
  if (!root.has("monitors")) return;
  std::vector<std::string> names;
  for (const auto& p : participants_) names.push_back(p->name());
  std::set<std::string> files;
  for (const config::Node& m : root["monitors"].items()) {
    Monitor mon;
    mon.name = m.string("name");
    if (mon.name.empty() || mon.name.find('/') != std::string::npos || mon.name == "coupling")
      m["name"].fail(
          "a monitor name becomes DIR/<name>.csv: it must be non-empty, without '/', and not "
          "'coupling'");
    if (!files.insert(mon.name).second) m["name"].fail("two monitors are named '" + mon.name + "'");
    const config::Node qn = m["quantities"];
    const std::vector<std::string> qs = m.strings("quantities");
    for (std::size_t i = 0; i < qs.size(); ++i) {
      const config::Node q = qn.is_sequence() ? qn[i] : qn;
      const auto [pname, quantity] = split_dot(q, "a quantity");
      Participant* p = participant(pname);
      if (!p)
        q.fail("unknown participant '" + pname + "'; participants: " + join_names(names) +
               did_you_mean(pname, names));
      std::vector<std::string> known;
      for (const auto& v : p->monitors()) known.push_back(v.name);
      if (std::find(known.begin(), known.end(), quantity) == known.end())
        q.fail("participant '" + pname + "' reports no quantity '" + quantity + "'; it reports: " +
               (known.empty() ? "nothing" : join_names(known)) + did_you_mean(quantity, known));
      mon.quantities.emplace_back(p, quantity);
    }
    monitors_.push_back(std::move(mon));
  }
}

// ---------------------------------------------------------------------------------------------
// Running

PvdSeries& CaseRun::pvd(const std::string& series) {
  for (auto& [n, s] : pvds_)
    if (n == series) return s;
  pvds_.emplace_back(series, PvdSeries(output_dir_ / "vtk" / (series + ".pvd")));
  return pvds_.back().second;
}

void CaseRun::write_output(int frame, double time) {
  Stopwatch clock;
  const fs::path vtk = output_dir_ / "vtk";
  for (auto& p : participants_) {
    OutputFrame f{vtk, p->name(), frame, time, vtk_options_};
    p->write_output(f);  // counted as output time, not the participant's
    for (const auto& [series, file] : p->output_files()) {
      if (fs::path(file).has_parent_path() || file.empty() || file.front() == '.')
        throw Error("participant '" + p->name() + "' wrote the output file '" + file +
                    "', which is not a plain file name inside " + vtk.string());
      pvd(p->name() + "_" + series).add(time, file);
    }
    // interface meshes with their exchanged data
    for (const auto& im : p->meshes()) {
      VtkArrays arrays;
      for (const auto& e : exchanges_) {
        if (&e->from() == p.get() && e->from_mesh() == im.mesh.name() &&
            e->sent().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->sent());
        if (&e->to() == p.get() && e->to_mesh() == im.mesh.name() &&
            e->received().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->received());
      }
      if (arrays.empty() || im.mesh.size() > 200000) continue;
      const std::string file =
          fmt::format("{}_interface_{}_{:06d}.vtp", p->name(), im.mesh.name(), frame);
      write_vtp(vtk / file, im.mesh, arrays, {}, nullptr, vtk_options_);
      pvd(p->name() + "_interface_" + im.mesh.name()).add(time, file);
    }
  }
  summary_.output_seconds += clock.seconds();
}

void CaseRun::run() {
  if (options_.check_only) return;
  auto logger = log::get("coupling");
  Stopwatch wall;
  const bool resume = !options_.resume_dir.empty();
  fs::path resume_file;
  if (resume) {
    resume_file = newest_restart_file();
    if (const std::string why = restart_blocker(); !why.empty())
      throw Error("cannot resume from " + resume_file.string() + ": " + why);
  }
  // A resumed run changes nothing in its folder before the restart file has been read and
  // accepted (read_restart_file() below); a new run prepares the folder here.
  if (!resume) {
    Stopwatch clock;  // the output folder and an earlier run's VTK files: output time
    fs::create_directories(output_dir_ / "vtk");
    if (const int removed = remove_pvd_series(output_dir_ / "vtk"); removed > 0)
      logger->info("removed {} VTK files of an earlier run from {}", removed,
                   (output_dir_ / "vtk").string());
    summary_.output_seconds += clock.seconds();
  }

  std::vector<std::pair<std::string, std::string>> columns = {{"time", "s"}, {"iterations", ""}};
  for (const auto& c : scheme_->residual_columns()) columns.push_back(c);
  for (const Exchange* e : audited_) columns.emplace_back("imbalance " + e->label(), "");
  for (const auto& p : energy_pairs_) {
    columns.emplace_back("work on " + p.a->name() + " by " + p.b->name(), "J");
    columns.emplace_back("work on " + p.b->name() + " by " + p.a->name(), "J");
    columns.emplace_back("energy created " + p.label, "J");
  }
  coupling_csv_ = CsvSeries(output_dir_ / "coupling.csv", "window", "", columns);
  for (auto& m : monitors_) {
    std::vector<std::pair<std::string, std::string>> mc;
    for (const auto& [p, q] : m.quantities) {
      std::string unit;  // only that quantity: monitors() would compute every one (energies)
      for (const auto& v : p->monitor_values({q}))
        if (v.name == q) unit = v.unit;
      mc.emplace_back(p->name() + "." + q, unit);
    }
    m.csv = CsvSeries(output_dir_ / (m.name + ".csv"), "time", "s", mc);
  }
  // The quantities each participant must report, asked for once per window, and where each
  // monitor column finds its value: (participant slot, position in what the solver returned),
  // the position remembered from the last window and checked by name (no search per window
  // unless a solver changes the order of its answer).
  struct Asked {
    Participant* p;
    std::vector<std::string> names;
    std::vector<MonitorValue> values;
  };
  std::vector<Asked> wanted;
  struct Column {
    std::size_t asked;
    const std::string* name;
    std::size_t at = 0;
  };
  std::vector<std::vector<Column>> columns_of(monitors_.size());
  for (std::size_t mi = 0; mi < monitors_.size(); ++mi)
    for (const auto& pq : monitors_[mi].quantities) {
      const auto& p = pq.first;  // not a structured binding: clang 14 cannot capture those
      const auto& q = pq.second;
      auto it =
          std::find_if(wanted.begin(), wanted.end(), [&](const Asked& a) { return a.p == p; });
      if (it == wanted.end()) it = wanted.insert(wanted.end(), Asked{p, {}, {}});
      it->names.push_back(q);
      columns_of[mi].push_back({static_cast<std::size_t>(it - wanted.begin()), &q});
    }
  std::vector<double> monitor_row;
  auto record_monitors = [&](double t, std::int64_t window) {
    for (Asked& a : wanted) {
      Stopwatch clock;  // the solver computes its quantities: its time, not the core's
      a.values = a.p->monitor_values(a.names);
      a.p->add_seconds(clock.seconds());
      for (const auto& mv : a.values)
        if (!std::isfinite(mv.value))
          throw Error(fmt::format(
              "window {} (t = {:.6g} s): participant '{}' reports {} = {} {}: the run is "
              "diverging; reduce time.window or the substep size, add damping, or check the "
              "materials and loads",
              window, t, a.p->name(), mv.name, mv.value, mv.unit));
    }
    for (std::size_t mi = 0; mi < monitors_.size(); ++mi) {
      monitor_row.clear();
      for (Column& c : columns_of[mi]) {
        const std::vector<MonitorValue>& got = wanted[c.asked].values;
        if (c.at >= got.size() || got[c.at].name != *c.name) {
          // the last value of that name, as the search before (NaN where the solver gave none)
          c.at = got.size();
          for (std::size_t k = 0; k < got.size(); ++k)
            if (got[k].name == *c.name) c.at = k;
        }
        monitor_row.push_back(c.at < got.size() ? got[c.at].value : std::nan(""));
      }
      Stopwatch csv_clock;  // formatting the row: output time, not the core's
      monitors_[mi].csv.record(t, monitor_row);
      summary_.output_seconds += csv_clock.seconds();
    }
  };
  auto flush_all = [&] {
    Stopwatch clock;
    coupling_csv_.flush();
    for (auto& m : monitors_) m.csv.flush();
    summary_.output_seconds += clock.seconds();
  };

  Progress progress;
  progress.next_output = output_every_;
  if (!resume) {
    flush_all();  // the headers
  } else {
    read_restart_file(resume_file, progress);
    fs::create_directories(output_dir_ / "vtk");
    summary_.resumed_from = progress.windows_done;
  }

  logger->info(
      "case '{}': {} windows of {:.6g} s to t = {:.6g} s, scheme {}, participants {}; output in "
      "{}{}",
      name_, window_count_, window_size_, static_cast<double>(window_count_) * window_size_,
      scheme_->name(),
      [&] {
        std::vector<std::string> n;
        for (auto& p : participants_) n.push_back(p->name());
        return join_names(n);
      }(),
      output_dir_.string(),
      resume ? fmt::format("; resumed after window {} from {}", progress.windows_done,
                           resume_file.filename().string())
             : std::string());

  const std::string blocker = restart_blocker();
  ProgressLine progress_line(window_count_);
  Stopwatch since_flush, since_restart;
  double flush_interval = 2.0;  // [s]
  bool warned_imbalance = false;
  try {
    if (!resume) {
      scheme_->initialize();
      check_window(0, 0.0);
      record_monitors(0.0, 0);
      write_output(progress.frame++, 0.0);
    }
    TimeWindow window(window_size_, 0, 1);
    std::vector<double> row;  // coupling.csv's row of the window
    for (std::int64_t n = progress.windows_done; n < window_count_; ++n) {
      window = TimeWindow(window_size_, n, 1);
      const WindowReport r = scheme_->advance(window);
      const double t = window.end();
      progress.windows_done = n + 1;
      summary_.windows = n + 1;
      summary_.iterations += r.iterations;
      summary_.max_window_iterations = std::max(summary_.max_window_iterations, r.iterations);
      if (!r.converged) ++summary_.unconverged_windows;
      // the audit first: where its totals are finite, the check need not read the values again
      const std::vector<double>& imbalance = audit_balance();
      check_window(n + 1, t, true);
      row.assign({t, static_cast<double>(r.iterations)});  // keeps its capacity
      row.insert(row.end(), r.residuals.begin(), r.residuals.end());
      row.insert(row.end(), imbalance.begin(), imbalance.end());
      for (auto& p : energy_pairs_) {
        const EnergyAudit a = audit_energy(p);
        row.insert(row.end(), {a.on_a, a.on_b, a.created()});
        p.passed += std::abs(a.on_a - p.last_a) + std::abs(a.on_b - p.last_b);
        p.last_a = a.on_a;
        p.last_b = a.on_b;
        p.over = a.created() > energy_tolerance_ * p.passed ? p.over + 1 : 0;
        if (p.over < kEnergyAuditWindows) continue;
        const std::string what = fmt::format(
            "window {} (t = {:.6g} s): the coupling between '{}' and '{}' has created {:.4g} J, "
            "{:.0f} % of the {:.4g} J that passed through their interface (work on '{}' {:.4g} J, "
            "on '{}' {:.4g} J; a lossless interface creates none), more than "
            "coupling.energy_tolerance {:.3g} for {} windows in a row: the coupled run is "
            "unstable; shorten time.window, add damping to the structure (e.g. "
            "analysis.rayleigh.beta) or use an implicit scheme",
            n + 1, t, p.a->name(), p.b->name(), a.created(), 100.0 * a.created() / p.passed,
            p.passed, p.a->name(), a.on_a, p.b->name(), a.on_b, energy_tolerance_,
            kEnergyAuditWindows);
        if (energy_stop_) {
          coupling_csv_.record(static_cast<double>(n + 1), row);
          record_monitors(t, n + 1);
          throw Error(what);
        }
        if (summary_.energy_warnings++ == 0)
          logger->warn("{}; further windows are counted in the summary", what);
      }
      for (std::size_t i = 0; i < imbalance.size(); ++i)
        if (imbalance[i] > balance_tolerance_) {
          ++summary_.imbalance_warnings;
          if (!warned_imbalance)
            logger->warn(
                "window {} (t = {:.6g} s): exchange {} arrives off by {:.3g} of what was sent "
                "(coupling.balance_tolerance {:.3g}); the mapper does not conserve its total: use "
                "a conservative constraint or mapper (area-balanced for tractions); further "
                "windows are counted in the summary",
                n + 1, t, audited_[i]->label(), imbalance[i], balance_tolerance_);
          warned_imbalance = true;
        }
      Stopwatch csv_clock;
      coupling_csv_.record(static_cast<double>(n + 1), row);
      summary_.output_seconds += csv_clock.seconds();
      record_monitors(t, n + 1);
      const bool last = n + 1 == window_count_;
      if ((output_every_ > 0.0 && TimeWindow::reached(t, progress.next_output, window_size_)) ||
          last) {
        write_output(progress.frame++, t);
        while (output_every_ > 0.0 && TimeWindow::reached(t, progress.next_output, window_size_))
          progress.next_output = static_cast<double>(progress.frame) * output_every_;
      }
      const int signal = options_.stop_signal ? options_.stop_signal->load() : 0;
      const bool restart_due =
          (restart_every_windows_ > 0 && (n + 1) % restart_every_windows_ == 0) ||
          (restart_every_seconds_ > 0.0 && since_restart.seconds() >= restart_every_seconds_) ||
          (last && restart_at_end_) || signal != 0;
      if (restart_due) {
        if (blocker.empty()) {
          write_restart_file(progress);
          since_restart.restart();
        } else if (signal != 0) {
          logger->warn("no restart file: {}", blocker);
        }
      }
      // CSV files are rewritten whole at each flush (always complete on disk): flush every 2 s,
      // or less often once a flush takes longer than 2 % of the interval (very long runs)
      if (since_flush.seconds() > flush_interval) {
        Stopwatch flush_clock;
        flush_all();
        flush_interval = std::max(2.0, 50.0 * flush_clock.seconds());
        since_flush.restart();
      }
      progress_line.update(n + 1, t, r.iterations);
      if (signal != 0) {
        summary_.stopped_by_signal = signal;
        progress_line.finish();
        logger->warn("stopped by signal {} after window {} (t = {:.6g} s){}", signal, n + 1, t,
                     summary_.last_restart.empty()
                         ? std::string()
                         : "; continue with: partita run CASE --resume " + output_dir_.string());
        break;
      }
    }
  } catch (...) {
    progress_line.finish();
    flush_all();  // the complete rows so far stay readable
    throw;
  }
  progress_line.finish();
  flush_all();
  Stopwatch close_clock;
  coupling_csv_.close();
  for (auto& m : monitors_) m.csv.close();
  summary_.output_seconds += close_clock.seconds();
  for (auto& p : participants_) {
    Stopwatch sc;
    p->finalize();
    p->add_seconds(sc.seconds());
  }

  summary_.wall_seconds = wall.seconds();
  double accounted = summary_.output_seconds;
  for (auto& p : participants_) {
    summary_.participant_seconds.emplace_back(p->name(), p->seconds());
    accounted += p->seconds();
  }
  for (auto& e : exchanges_) summary_.mapping_seconds += e->mapping_seconds();
  accounted += summary_.mapping_seconds;
  summary_.core_seconds = std::max(0.0, summary_.wall_seconds - accounted);

  std::string parts;
  for (const auto& [n, s] : summary_.participant_seconds)
    parts += fmt::format("{} {:.3f} s, ", n, s);
  logger->info(
      "summary: {} windows, {} iterations (mean {:.2f}, max {}{}); wall {:.3f} s = {}mapping "
      "{:.3f} s, "
      "output {:.3f} s, core {:.3f} s{}{}",
      summary_.windows, summary_.iterations, summary_.mean_iterations(),
      summary_.max_window_iterations,
      summary_.unconverged_windows
          ? fmt::format(", {} windows at max_iterations", summary_.unconverged_windows)
          : std::string(),
      summary_.wall_seconds, parts, summary_.mapping_seconds, summary_.output_seconds,
      summary_.core_seconds,
      summary_.energy_warnings
          ? fmt::format("; {} windows with the coupling creating energy beyond the tolerance",
                        summary_.energy_warnings)
          : std::string(),
      summary_.imbalance_warnings
          ? fmt::format("; {} windows with an exchange off balance", summary_.imbalance_warnings)
          : std::string());
}

}  // namespace partita::coupling
