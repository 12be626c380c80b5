// CaseRun, building the participants from the validated case: the scheme order, each
// participant's solver (or, in a distributed run, a proxy of the one in another process, or the
// server of this process's own), the meshes handed from one participant to another, and what
// `partita check` puts in place of an external program.
#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include <fmt/format.h>

#include "case_keys.hpp"
#include "external_stand_in.hpp"
#include "plain_name.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/run/case_run.hpp"
#include "partita/run/remote_participant.hpp"
#include "service_settings.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

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

  if (options_.ranks && options_.ranks->size() > 1 && names.size() != 1 &&
      options_.distributed.participant.empty())
    ps.fail(fmt::format(
        "this case has {} participants ({}) and runs on {} ranks (mpirun -n {}): a case of one "
        "participant runs on several ranks; run each participant in a process of its own, e.g. "
        "mpirun -n 1 partita run CASE --participant {} : -n 1 partita run CASE --participant {}",
        names.size(), join_names(names), options_.ranks->size(), options_.ranks->size(),
        names[0], names[1]));

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
    ctx.ranks = options_.ranks;  // (a case of one participant: checked above)
    log::get("coupling")->debug("setting up participant '{}' ({})", name, entry.name);
    Stopwatch setup;
    std::unique_ptr<Solver> solver = entry.factory(ctx);
    if (setup.seconds() > 1.0)
      log::get("coupling")
          ->info("set-up of participant '{}' ({}): {:.1f} s", name, entry.name, setup.seconds());
    if (!solver) pn.fail("solver '" + entry.name + "' could not be built");
    if (ctx.ranks && ctx.ranks->size() > 1 && !ctx.ranks->claimed() &&
        !options_.distributed.participant.empty())
      pn["solver"].fail(fmt::format(
          "participant '{}' runs on {} processes (-n {} before its --participant), and its solver "
          "'{}' does not run on several ranks; give it one process: -n 1 partita run "
          "CASE --participant {}",
          name, ctx.ranks->size(), ctx.ranks->size(), entry.name, name));
    built.push_back(Built{name, pn, entry.name, std::move(solver)});
  }

  if (follows()) {  // (kept alive: its solver follows the leader's, ParticipantRanks::follow())
    participants_.push_back(std::make_unique<LocalParticipant>(
        built.front().name, std::move(built.front().solver), Substeps{}));
    return;
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

}  // namespace partita::run
