// CaseRun, phase one: building a run from a validated case (participants, meshes handed over,
// exchanges and their mappers, the scheme, monitors, the audits' pairs).
#include "partita/run/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/explicit_scheme.hpp"
#include "partita/run/progress_line.hpp"
#include "partita/run/remote_participant.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/run/sweep.hpp"
#include "external_stand_in.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace fs = std::filesystem;

namespace {
// Above this many windows a run is almost surely a typing error in time.window or time.end.
constexpr double kWindowWarning = 1e8;
}  // namespace

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

std::vector<std::string> CaseRun::external_participants() const {
  std::vector<std::string> names;
  for (const auto& p : participants_)
    if (dynamic_cast<const ExternalStandIn*>(p.get())) names.push_back(p->name());
  return names;
}

CaseRun::CaseRun(const fs::path& case_file, const Registries& registries, RunOptions options)
    : registries_(registries), options_(std::move(options)) {
  const config::Node loaded =
      config::Node::load_file(case_file, options_.overrides, options_.override_origins);
  case_hash_ = run::case_hash(loaded);
  const config::Node root = loaded.validated(case_spec(registries));
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
  if (serves()) {  // the controller builds the rest; this process serves its participant
    if (root.has("coupling")) served_coupling_ = root["coupling"];  // (the mappers it runs)
    return;
  }
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
    if (coupling.has("concurrent") && coupling.boolean("concurrent") && !scheme_->parallel())
      coupling["concurrent"].fail(
          "scheme '" + scheme_->name() +
          "' runs its participants one after the other (each reads what the one before it "
          "wrote in the window); 'concurrent' applies to explicit-parallel and implicit-parallel");
    scheme_->set_concurrent(coupling.boolean("concurrent"));
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
  // done on them through the meshes they read on; not through a prescribed mesh (a driven body's
  // surface: the work it does is the reader's input).
  for (const auto& e : exchanges_) {
    Participant* reader = &e->to();
    Participant* writer = &e->from();
    if (reader == writer || !reader->interface_work(e->to_mesh())) continue;
    if (const InterfaceMesh* from = writer->find_mesh(e->from_mesh()); from && from->prescribed)
      continue;
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
  build_energy_balance(root);
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

// (partita check) The meshes an external program must have for the case's exchanges that name
// it: each with the fields it reads and writes there (as the other end declares them) and the
// other end's points, so that the exchanges, their mappers and the scheme build as in a run.
// What the program really declares is checked when it joins (the handshake).
static std::vector<InterfaceMesh> stand_in_meshes(
    const config::Node& coupling, const std::string& name,
    const std::function<const std::vector<InterfaceMesh>*(const std::string&)>& built_meshes) {
  std::vector<InterfaceMesh> meshes;
  if (!coupling.has("exchanges") || !coupling["exchanges"].is_sequence()) return meshes;
  for (const config::Node& item : coupling["exchanges"].items()) {
    if (!item.is_map() || !item.has("data") || !item.has("from") || !item.has("to")) continue;
    const auto [from_p, from_m] = split_dot(item["from"], "a mesh");
    const auto [to_p, to_m] = split_dot(item["to"], "a mesh");
    const bool reads = to_p == name;
    if (!reads && from_p != name) continue;
    const std::string mesh = reads ? to_m : from_m, data = item.string("data");
    // the other end, where it is built: its mesh's points and its declaration of the field
    const InterfaceMesh* other = nullptr;
    if (const auto* m = built_meshes(reads ? from_p : to_p))
      for (const auto& im : *m)
        if (im.mesh.name() == (reads ? from_m : to_m)) other = &im;
    auto at = std::find_if(meshes.begin(), meshes.end(),
                           [&](const InterfaceMesh& m) { return m.mesh.name() == mesh; });
    if (at == meshes.end()) {
      InterfaceMesh m;
      if (other) {
        m.mesh = Mesh(mesh, other->mesh.points(), other->mesh.triangles());
        if (other->mesh.has_weights()) m.mesh.set_weights(other->mesh.weights());
      } else {
        m.mesh = Mesh(mesh, Mesh::Points::Zero(1, 3));
      }
      meshes.push_back(std::move(m));
      at = std::prev(meshes.end());
    }
    DataSpec spec{data, 1, "", DataKind::intensive};
    if (other)
      for (const auto& d : reads ? other->writes : other->reads)
        if (d.name == data) spec = d;
    auto& fields = reads ? at->reads : at->writes;
    if (std::none_of(fields.begin(), fields.end(), [&](const DataSpec& d) { return d.name == data; }))
      fields.push_back(spec);
  }
  return meshes;
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

  const auto& dist = options_.distributed;
  if (!dist.participant.empty() &&
      std::find(names.begin(), names.end(), dist.participant) == names.end())
    throw Error("--participant " + dist.participant + ": the case has no participant '" +
                dist.participant + "'; participants: " + join_names(names) +
                did_you_mean(dist.participant, names));
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
              join_names(registries_.solvers.names()) + ", or external");
    if (pn.string("solver") == "external") {  // a program of its own (partita::mpi::ExternalParticipant)
      if (options_.check_only) continue;  // checked with a stand-in (below), and when it joins
      if (runs_here(name))
        pn["solver"].fail(
            "participant '" + name + "' is an external program (solver: external), which joins a "
            "run over MPI through partita::mpi::ExternalParticipant: run the other participants "
            "with --participant and the program beside them, e.g. mpirun -n 1 partita run CASE "
            "--participant OTHER : -n 1 ./program CASE");
      continue;  // its keys are the program's own
    }
    if (const std::string solver = pn["solver"].as_string(); !registries_.solvers.contains(solver))
      pn["solver"].fail(registries_.solvers.unknown_message(solver) +
                        " (a solver from a plugin needs its library: plugins: [LIB] in the case, "
                        "or partita --plugin LIB)");
    const auto& entry = registries_.solvers.get(pn["solver"]);
    config::Node validated = pn;
    if (entry.spec) {
      auto spec = std::make_shared<config::Spec>(*entry.spec);
      if (!spec->find("solver")) spec->string("solver", "the registered solver's name").required();
      validated = pn.validated(spec);
    }
    if (!runs_here(name)) continue;  // another process builds it
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

  if (serves()) {
    serve_handshake(built.front().solver, substeps, coupled);
    return;
  }
  // The participants in other processes: their hellos (meshes and what they ask for).
  std::vector<Hello> hellos;
  for (const auto& [pname, channel] : dist.servers) hellos.push_back(receive_hello(*channel, pname, case_hash_));
  for (const std::string& name : order) {
    if (runs_here(name)) continue;
    bool found = false;
    for (const Hello& h : hellos) found = found || h.participant == name;
    if (!found)
      throw Error("participant '" + name + "' has no process: start one with ': -n 1 partita run " +
                  "CASE --participant " + name + "' on the mpirun line");
  }
  // The meshes a participant offers others, wherever it runs.
  auto offered = [&](const std::string& pname) -> const std::vector<InterfaceMesh>* {
    for (const auto& b : built)
      if (b.name == pname) return &b.solver->meshes();
    for (const Hello& h : hellos)
      if (h.participant == pname) return &h.meshes;
    return nullptr;
  };
  auto find_offered = [&](const std::string& source, const std::string& receiver,
                          const std::function<void(const std::string&)>& fail) -> const Mesh& {
    const auto dot = source.find('.');
    const std::string pname = source.substr(0, dot);
    const std::string mname = dot == std::string::npos ? "" : source.substr(dot + 1);
    const std::vector<InterfaceMesh>* from = offered(pname);
    if (options_.check_only && dot != std::string::npos && !from && ps.has(pname) &&
        ps[pname].is_map() &&
        ps[pname].has("solver") && ps[pname].string("solver") == "external")
      fail(fmt::format(
          "'{}' is a mesh of participant '{}', an external program (solver: external): its "
          "meshes are known only when it joins the run, and the handshake checks this one then; "
          "partita check cannot build participant '{}', which takes it as a surface (check the "
          "case by running it with the program: mpirun -n 1 partita run CASE --participant {} "
          ": -n 1 ./program CASE)",
          source, pname, receiver, receiver));
    if (dot == std::string::npos || !from)
      fail("'" + source + "' names no participant's mesh (participant.mesh); participants: " +
           join_names(names) + did_you_mean(pname, names));
    if (pname == receiver) fail("a participant cannot take a mesh from itself");
    std::vector<std::string> known;
    const InterfaceMesh* found = nullptr;
    for (const auto& m : *from) {
      known.push_back(m.mesh.name());
      if (m.mesh.name() == mname) found = &m;
    }
    if (!found)
      fail("participant '" + pname + "' has no mesh '" + mname + "'; its meshes: " +
           join_names(known) + did_you_mean(mname, known));
    if (found->mesh.num_triangles() == 0)
      fail("mesh '" + source + "' has no triangles (a point set): a surface is needed");
    return found->mesh;
  };
  std::vector<Ready> ready;
  for (std::size_t i = 0; i < hellos.size(); ++i) {
    std::vector<std::pair<std::string, Mesh>> meshes;
    for (const auto& [rname, source] : hellos[i].mesh_requests)
      meshes.emplace_back(rname, find_offered(source, hellos[i].participant, [&](const std::string& why) {
                            ps[hellos[i].participant].fail(why);
                          }));
    ready.push_back(complete_handshake(*dist.servers[i].second, meshes));
  }

  // Surfaces handed from one participant to another (an FE face as a DEM wall): once every
  // participant is built, before anyone's meshes() is used for the exchanges.
  for (auto& b : built)
    for (const MeshRequest& req : b.solver->mesh_requests())
      b.solver->receive_mesh(
          req.name, find_offered(req.source, b.name,
                                 [&](const std::string& why) { req.where.fail(why); }));

  for (const std::string& name : order) {
    const config::Node pn = ps[name];
    if (options_.check_only && pn.string("solver") == "external") {
      participants_.push_back(std::make_unique<ExternalStandIn>(
          name, stand_in_meshes(coupling, name,
                                [&](const std::string& pname) -> const std::vector<InterfaceMesh>* {
                                  if (const Participant* p = participant(pname)) return &p->meshes();
                                  for (const auto& x : built)  // (those after it in the order)
                                    if (x.name == pname && x.solver) return &x.solver->meshes();
                                  return nullptr;
                                })));
      continue;
    }
    auto b = std::find_if(built.begin(), built.end(), [&](const Built& x) { return x.name == name; });
    Substeps s = substeps.count(name) ? substeps[name] : Substeps{};
    if (!coupled) s.automatic = true;  // alone: as many steps per window as its stability needs
    // A fixed number of substeps must not exceed the solver's stable time step.
    std::size_t remote = 0;
    while (b == built.end() && dist.servers[remote].first != name) ++remote;
    const double stable =
        b != built.end() ? b->solver->stable_time_step() : ready[remote].stable_time_step;
    if (!s.automatic && TimeWindow::longer_than(window_size_ / s.count, stable)) {
      const config::Node where = substeps.count(name) ? coupling["substeps"][name] : pn;
      where.fail(fmt::format(
          "participant '{}' would step {:.4g} s (window {:.4g} s / {} substeps), above its stable "
          "time step {:.4g} s; use substeps: {{{}: {}}} or more, or {{{}: auto}}",
          name, window_size_ / s.count, window_size_, s.count, stable, name,
          TimeWindow::substeps_for(window_size_, stable), name));
    }
    if (b != built.end())
      participants_.push_back(std::make_unique<LocalParticipant>(name, std::move(b->solver), s));
    else
      participants_.push_back(std::make_unique<RemoteParticipant>(name, *dist.servers[remote].second,
                                                                  std::move(ready[remote])));
    if (b == built.end() && pn.string("solver") == "external")  // named in messages
      external_programs_[name] = fmt::format("'{}' of {}", hellos[remote].program,
                                             dist.servers[remote].second->peer());
    if (coupled && participants_.back()->meshes().empty())
      pn.fail("solver '" + pn.string("solver") + "' of participant '" + name +
              "' exposes no coupling mesh");
    for (const auto& m : participants_.back()->meshes())
      check_plain_name(pn, m.mesh.name(),
                       "the mesh name '" + m.mesh.name() + "' of '" + name + "'");
  }
}

// A server's side of the handshake: say what it offers and asks for, take the meshes it asked
// for, become the participant the controller talks to.
void CaseRun::serve_handshake(std::unique_ptr<Solver>& solver,
                              std::map<std::string, Substeps>& substeps, bool coupled) {
  const std::string& name = options_.distributed.participant;
  Hello h;
  h.case_hash = case_hash_;
  h.participant = name;
  h.program = "partita";
  h.meshes = solver->meshes();
  const std::vector<MeshRequest> requests = solver->mesh_requests();
  for (const MeshRequest& r : requests) h.mesh_requests.emplace_back(r.name, r.source);
  ParticipantServer server(*options_.distributed.controller, options_.stop_signal);
  for (auto& [rname, mesh] : server.hello(h)) solver->receive_mesh(rname, mesh);
  Substeps s = substeps.count(name) ? substeps[name] : Substeps{};
  if (!coupled) s.automatic = true;
  auto local = std::make_unique<LocalParticipant>(name, std::move(solver), s);
  served_ = local.get();
  participants_.push_back(std::move(local));
}

void CaseRun::build_exchanges(const config::Node& coupling) {
  const std::vector<config::Node> items = coupling["exchanges"].items();
  if (items.empty()) coupling["exchanges"].fail("a coupled case needs at least one exchange");

  struct Resolved {
    Participant* p;
    const InterfaceMesh* mesh;
  };
  auto resolve = [&](const config::Node& n) {
    const auto [pname, mname] = split_dot(n, "a mesh");
    Participant* p = named_participant(n, pname);
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
      bool writes_it = false;
      for (const auto& d : to.mesh->writes) writes_it = writes_it || d.name == data;
      // Two participants that both prescribe the same field on one interface: each computes it,
      // neither takes it (both move the interface, or both push on it).
      const std::string pairing =
          writes_it ? "; '" + to.p->name() + "' writes '" + data +
                          "' on that mesh itself, and two participants cannot both prescribe "
                          "one field on an interface: one side moves it (writes displacement), "
                          "the other pushes on it (writes force or traction), see "
                          "docs/writing_an_adapter.md, 'Which written and read fields pair'"
                    : std::string();
      item["data"].fail("participant '" + to.p->name() + "' does not read '" + data +
                        "' on mesh '" + to.mesh->mesh.name() + "'; it reads: " +
                        (r.empty() ? "nothing" : join_names(r)) + did_you_mean(data, r) +
                        pairing);
    }
    if (ws->components != rs->components)
      item["data"].fail("'" + data + "' has " + std::to_string(ws->components) +
                        " components where '" + from.p->name() + "' writes it but " +
                        std::to_string(rs->components) + " where '" + to.p->name() + "' reads it");
    for (const auto& e : exchanges_)
      if (&e->to() == to.p && e->to_mesh() == to.mesh->mesh.name() && e->data() == data)
        item.fail("'" + data + "' on " + to.p->name() + "." + to.mesh->mesh.name() +
                  " already has a sender (" + e->label() + ")");
    std::unique_ptr<Mapper> mapper = exchange_mapper(
        item, *ws, from.mesh->mesh, to.mesh->mesh,
        fmt::format("'{}' {}.{} -> {}.{}", data, from.p->name(), from.mesh->mesh.name(),
                    to.p->name(), to.mesh->mesh.name()));
    const ReaderSees rsee =
        item.string("reader_sees") == "constant" ? ReaderSees::constant : ReaderSees::linear;
    const WriterCombines wc =
        item.string("writer_combines") == "last" ? WriterCombines::last : WriterCombines::average;
    exchanges_.push_back(std::make_unique<Exchange>(
        data, Exchange::End{from.p, from.mesh->mesh.name()},
        Exchange::End{to.p, to.mesh->mesh.name()}, *ws, std::move(mapper), rsee, wc));
    Exchange& e = *exchanges_.back();
    e.set_map_on(item.string("map_on") == "sender" ? MapOn::sender : MapOn::receiver);
    // A receiver in another process maps what it reads on its side (it is sent the sender's
    // values); this process maps it as well, for the checks, audits and restart files. (An
    // external program, which maps nothing, is sent mapped values.)
    if (auto* remote = dynamic_cast<RemoteParticipant*>(to.p);
        remote && remote->maps_inputs() && e.map_on() == MapOn::receiver) {
      remote->prepare_mapping(static_cast<std::size_t>(&item - items.data()), e.to_mesh(), data,
                              *from.mesh);
      e.set_mapped_by_receiver(true);
    }
  }
}

std::unique_ptr<Mapper> CaseRun::exchange_mapper(const config::Node& item, const DataSpec& ws,
                                                 const Mesh& from, const Mesh& to,
                                                 const std::string& label) const {
  Constraint constraint =
      ws.kind == DataKind::extensive ? Constraint::conservative : Constraint::consistent;
  if (item.has("constraint"))
    constraint = item.string("constraint") == "conservative" ? Constraint::conservative
                                                             : Constraint::consistent;
  std::unique_ptr<Mapper> mapper =
      create_mapper(registries_.mappers, MapperContext{item["mapper"], constraint});
  Stopwatch setup;
  mapper->compute(from, to);
  if (setup.seconds() > 1.0)
    log::get("coupling")->info("set-up of the mapping of {}: {:.1f} s", label, setup.seconds());
  return mapper;
}

// A server's side of an exchange it maps: the same mapper as the controller's, from the same
// case item and the same meshes (the sender's handed over by the controller, bit for bit).
ServerMapping CaseRun::server_mapping(std::size_t exchange, const InterfaceMesh& from,
                                      const InterfaceMesh& to) const {
  const std::vector<config::Node> items = served_coupling_["exchanges"].items();
  if (exchange >= items.size())
    throw Error(fmt::format("the controller asked for the mapping of exchange {} of {}", exchange,
                            items.size()));
  const config::Node& item = items[exchange];
  const std::string data = item.string("data");
  const auto ws = std::find_if(from.writes.begin(), from.writes.end(),
                               [&](const DataSpec& d) { return d.name == data; });
  if (ws == from.writes.end())
    item["data"].fail("the sender's mesh '" + from.mesh.name() + "' does not write '" + data + "'");
  ServerMapping m;
  m.mapper = exchange_mapper(item, *ws, from.mesh, to.mesh,
                             fmt::format("'{}' {} -> {}.{} (on the receiver's side)", data,
                                         item.string("from"), served_->name(), to.mesh.name()));
  return m;
}

Participant* CaseRun::named_participant(const config::Node& n, const std::string& name) const {
  if (Participant* p = participant(name)) return p;
  std::vector<std::string> names;
  for (const auto& p : participants_) names.push_back(p->name());
  n.fail("unknown participant '" + name + "'; participants: " + join_names(names) +
         did_you_mean(name, names));
}

CaseRun::NamedQuantity CaseRun::resolve_quantity(const config::Node& q) const {
  const auto [pname, quantity] = split_dot(q, "a quantity");
  Participant* p = named_participant(q, pname);
  if (dynamic_cast<const ExternalStandIn*>(p))  // (partita check) known when the program joins
    return {p, quantity, {}};
  std::vector<std::string> known;
  std::string unit;
  for (const auto& v : p->monitors()) {
    known.push_back(v.name);
    if (v.name == quantity) unit = v.unit;
  }
  if (std::find(known.begin(), known.end(), quantity) == known.end())
    q.fail("participant '" + pname + "' reports no quantity '" + quantity + "'; it reports: " +
           (known.empty() ? "nothing" : join_names(known)) + did_you_mean(quantity, known));
  return {p, quantity, unit};
}

// The items of a list of strings (a single string is a list of one), each with its node.
static std::vector<config::Node> string_items(const config::Node& list) {
  if (!list.is_sequence()) return {list};
  return list.items();
}

void CaseRun::build_energy_balance(const config::Node& root) {
  if (!root.has("energy")) return;
  const config::Node en = root["energy"];
  std::vector<EnergyBalance::Term> terms;
  std::set<std::string> seen;
  for (const auto& [key, role] : {std::pair{"inputs", EnergyBalance::Role::input},
                                  std::pair{"stored", EnergyBalance::Role::stored},
                                  std::pair{"dissipated", EnergyBalance::Role::dissipated}}) {
    if (!en.has(key)) continue;
    for (const config::Node& q : string_items(en[key])) {
      const NamedQuantity nq = resolve_quantity(q);
      const std::string full = nq.participant->name() + "." + nq.quantity;
      if (nq.unit != "J" && !dynamic_cast<const ExternalStandIn*>(nq.participant))
        q.fail("'" + full + "' is in " + (nq.unit.empty() ? "no unit" : nq.unit) +
               ": an energy term must be an energy or a work in J");
      if (!seen.insert(full).second)
        q.fail("'" + full + "' is named twice in the energy section: each term counts once");
      terms.push_back({role, nq.participant->name(), nq.quantity, nq.unit});
      energy_terms_.emplace_back(nq.participant, nq.quantity);
    }
  }
  EnergyBalance::Settings s;
  if (en.has("tolerance")) s.tolerance = en.real("tolerance");
  s.stop = en.string("on_exceeded") == "stop";
  if (en.has("floor")) s.floor = en.real("floor");
  s.coupling_column = !energy_pairs_.empty();
  s.count_coupling = en.string("coupling") == "counted";
  if (s.count_coupling && energy_pairs_.empty())
    en["coupling"].fail(
        "no pair of participants reports the work through its interfaces (the energy audit), "
        "so there is no coupling term to count; leave out coupling: counted");
  energy_ = std::make_unique<EnergyBalance>(std::move(terms), s);
}

void CaseRun::build_monitors(const config::Node& root) {
  if (!root.has("monitors")) return;
  std::set<std::string> files;
  for (const config::Node& m : root["monitors"].items()) {
    Monitor mon;
    mon.name = m.string("name");
    if (mon.name.empty() || mon.name.find('/') != std::string::npos || mon.name == "coupling")
      m["name"].fail(
          "a monitor name becomes DIR/<name>.csv: it must be non-empty, without '/', and not "
          "'coupling'");
    if (!files.insert(mon.name).second) m["name"].fail("two monitors are named '" + mon.name + "'");
    std::vector<std::string> columns;
    for (const config::Node& q : string_items(m["quantities"])) {
      const NamedQuantity nq = resolve_quantity(q);
      mon.quantities.emplace_back(nq.participant, nq.quantity);
      columns.push_back(nq.participant->name() + "." + nq.quantity);
    }
    if (m.has("plots")) {
      // Each plot draws columns of this monitor's CSV: x and y must be among its quantities.
      const auto column = [&](const config::Node& q) {
        const std::string name = q.as_string();
        if (std::find(columns.begin(), columns.end(), name) == columns.end())
          q.fail("'" + name + "' is not one of the quantities of monitor '" + mon.name +
                 "' (a plot draws its columns): " + join_names(columns) +
                 did_you_mean(name, columns) + "; add it to the monitor's quantities");
        return name;
      };
      std::set<std::string> xs;
      for (const config::Node& plot : m["plots"].items()) {
        std::vector<std::string> xy = {column(plot["x"])};
        if (!xs.insert(xy.front()).second)
          plot["x"].fail("two plots of monitor '" + mon.name + "' have x '" + xy.front() +
                         "' (both would be " + mon.name + "_vs_" + xy.front() +
                         ".png): put their y in one list");
        for (const config::Node& y : string_items(plot["y"])) {
          xy.push_back(column(y));
          if (xy.back() == xy.front())
            y.fail("'" + xy.front() + "' is the plot's x: a y must be another quantity");
        }
        mon.plots.push_back(std::move(xy));
      }
    }
    monitors_.push_back(std::move(mon));
  }
}

// ---------------------------------------------------------------------------------------------
// Running

}  // namespace partita::run
