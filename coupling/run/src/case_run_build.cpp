// CaseRun, building a run from a validated case: the time, the exchanges and their mappers, the
// scheme (the participants: case_run_participants.cpp; the services' settings:
// case_run_services.cpp).
#include "partita/run/case_run.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include <fmt/format.h>

#include "case_keys.hpp"
#include "external_stand_in.hpp"
#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/run/remote_participant.hpp"
#include "partita/run/service.hpp"
#include "partita/run/sweep.hpp"
#include "plain_name.hpp"
#include "restart_file.hpp"
#include "service_settings.hpp"
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
  read_service_settings(root);
  if (root.has("output") && root["output"].has("scripts"))
    for (const config::Node& sn : root["output"]["scripts"].items()) {
      const fs::path script = case_dir_ / sn.as_string();
      if (!fs::exists(script))
        sn.fail("post-processing script '" + script.string() + "' does not exist");
      scripts_.push_back(script);
    }

  build_participants(root);
  if (follows()) return;  // the leader's solver drives this process's
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
    settings_->balance_tolerance = coupling.real("balance_tolerance");
    settings_->energy_tolerance = coupling.real("energy_tolerance");
    settings_->energy_stop = coupling.string("on_energy_created") == "stop";
  }
  build_energy_pairs();
  build_energy_balance(root);
  state_ = std::make_unique<RunState>();
  state_->name = name_;
  state_->identity = identity_;
  state_->window_size = window_size_;
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
        const std::string swept = " (the swept value " + par.values[i] + " of " + par.key +
                                  ", as its variants will run it)";
        if (!e.where().file.empty() || !e.key_path().empty())  // the same text, still located
          throw Error(e.where(), e.key_path(), e.detail() + swept);
        throw Error(std::string(e.what()) + swept);
      }
    }
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

}  // namespace partita::run
