// CaseRun, building the services' settings from the validated case (service_settings.hpp), and
// the services themselves, in the order they observe a finished window.
#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "case_keys.hpp"
#include "external_stand_in.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/case_run.hpp"
#include "restart_file.hpp"
#include "service_settings.hpp"
#include "services/balance_audit.hpp"
#include "services/coupling_csv.hpp"
#include "services/csv_flush.hpp"
#include "services/energy_balance_service.hpp"
#include "services/health_check.hpp"
#include "services/progress.hpp"
#include "services/stop_requests.hpp"
#include "services/vtk_output.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

void CaseRun::read_service_settings(const config::Node& root) {
  settings_ = std::make_unique<ServiceSettings>();
  ServiceSettings& s = *settings_;
  if (root.has("output") && root["output"].has("every")) s.output_every = root["output"].real("every");
  if (root.has("output") && root["output"].has("restart")) {
    const config::Node r = root["output"]["restart"];
    if (r.has("every_windows")) s.restart.every_windows = r.integer("every_windows");
    if (r.has("every_minutes")) s.restart.every_seconds = 60.0 * r.real("every_minutes");
    s.restart.keep = static_cast<int>(r.integer("keep"));
    s.restart.at_end = r.boolean("at_end");
  }
  if (root.has("output") && root["output"].has("vtk")) {
    const config::Node v = root["output"]["vtk"];
    s.vtk.format = vtk::parse_format(v.string("format"));
    s.vtk.zlib_level = static_cast<int>(v.integer("zlib_level"));
    s.vtk.precision = vtk::parse_precision(v.string("precision"));
  }
}

std::string CaseRun::restart_blocker() const {
  std::vector<Participant*> ps;
  for (const auto& p : participants_) ps.push_back(p.get());
  return run::restart_blocker(ps, external_programs_);
}

// The balance audit's exchanges (extensive data, or weighted points at both ends) and the energy
// audit's pairs: participants with exchanges both ways whose solvers report the work done on
// them through the meshes they read on; not through a prescribed mesh (a driven body's surface:
// the work it does is the reader's input).
void CaseRun::build_energy_pairs() {
  ServiceSettings& s = *settings_;
  for (const auto& e : exchanges_) {
    const bool extensive = e->spec().kind == DataKind::extensive;
    const bool weighted = e->from().find_mesh(e->from_mesh())->mesh.has_weights() &&
                          e->to().find_mesh(e->to_mesh())->mesh.has_weights();
    if (extensive || weighted) s.audited.push_back(e.get());
  }
  auto& pairs = s.energy_pairs;
  for (const auto& e : exchanges_) {
    Participant* reader = &e->to();
    Participant* writer = &e->from();
    if (reader == writer || !reader->interface_work(e->to_mesh())) continue;
    if (const InterfaceMesh* from = writer->find_mesh(e->from_mesh()); from && from->prescribed)
      continue;
    auto it = std::find_if(pairs.begin(), pairs.end(), [&](const EnergyAudit::Pair& p) {
      return (p.a == reader && p.b == writer) || (p.a == writer && p.b == reader);
    });
    if (it == pairs.end()) {
      pairs.push_back({reader->name() + "-" + writer->name(), reader, writer, {}, {}});
      it = std::prev(pairs.end());
    }
    auto& meshes = it->a == reader ? it->a_meshes : it->b_meshes;
    if (std::find(meshes.begin(), meshes.end(), e->to_mesh()) == meshes.end())
      meshes.push_back(e->to_mesh());
  }
  std::erase_if(pairs, [](const EnergyAudit::Pair& p) {
    return p.a_meshes.empty() || p.b_meshes.empty();
  });
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
      settings_->energy_terms.emplace_back(nq.participant, nq.quantity);
    }
  }
  EnergyBalance::Settings s;
  if (en.has("tolerance")) s.tolerance = en.real("tolerance");
  s.stop = en.string("on_exceeded") == "stop";
  if (en.has("floor")) s.floor = en.real("floor");
  if (en.has("every_windows"))
    settings_->energy_every = static_cast<int>(en.integer("every_windows"));
  s.coupling_column = !settings_->energy_pairs.empty();
  s.count_coupling = en.string("coupling") == "counted";
  if (s.count_coupling && settings_->energy_pairs.empty())
    en["coupling"].fail(
        "no pair of participants reports the work through its interfaces (the energy audit), "
        "so there is no coupling term to count; leave out coupling: counted");
  settings_->energy = std::make_unique<EnergyBalance>(std::move(terms), s);
}

void CaseRun::build_monitors(const config::Node& root) {
  if (!root.has("monitors")) return;
  std::set<std::string> files;
  for (const config::Node& m : root["monitors"].items()) {
    Monitors::Monitor mon;
    mon.name = m.string("name");
    if (m.has("every_windows")) mon.every = static_cast<int>(m.integer("every_windows"));
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
    settings_->monitors.push_back(std::move(mon));
  }
}

// The services, in the order they observe a finished window: the balance audit, the divergence
// stop (after the audit: where its totals are finite, the values need not be read again),
// coupling.csv, the monitors, the energy balance, the energy audit (after the files have their
// row of the window: a run it stops keeps them), VTK output, stop requests, restart files (after
// the stop requests: a signal writes one), the CSV flushes and the progress line.
void CaseRun::build_services() {
  ServiceSettings& s = *settings_;
  std::vector<Participant*> participants;
  for (const auto& p : participants_) participants.push_back(p.get());
  std::vector<const Exchange*> exchanges;
  for (const auto& e : exchanges_) exchanges.push_back(e.get());
  services_.clear();
  auto add = [&](auto service) -> auto& {
    auto& ref = *service;
    services_.push_back(std::move(service));
    return ref;
  };
  auto& balance = add(std::make_unique<BalanceAudit>(s.audited, s.balance_tolerance));
  add(std::make_unique<HealthCheck>(exchanges, participants, balance));
  auto energy_audit =
      std::make_unique<EnergyAudit>(s.energy_pairs, s.energy_tolerance, s.energy_stop);
  std::vector<Service*> csv_files;
  csv_files.push_back(&add(
      std::make_unique<CouplingCsv>(output_dir_ / "coupling.csv", *scheme_, balance, *energy_audit)));
  auto& monitors =
      add(std::make_unique<Monitors>(output_dir_, s.monitors, s.energy_terms, s.energy_every));
  csv_files.push_back(&monitors);
  if (s.energy) {
    csv_files.push_back(&add(std::make_unique<EnergyBalanceService>(
        output_dir_ / "energy.csv", std::move(s.energy), monitors, *energy_audit)));
  }
  add(std::move(energy_audit));
  add(std::make_unique<VtkOutput>(output_dir_, s.output_every, window_size_, s.vtk, participants,
                                  exchanges));
  add(std::make_unique<StopRequests>(options_.stop_signal, participants));
  RestartParts parts;
  parts.run = state_.get();
  parts.scheme = scheme_.get();
  parts.participants = participants;
  auto restart = std::make_unique<RestartFiles>(output_dir_, s.restart, restart_blocker());
  RestartFiles& restart_ref = *restart;
  add(std::move(restart));
  add(std::make_unique<CsvFlush>(csv_files));
  add(std::make_unique<Progress>(window_count_));
  for (const auto& x : services_) parts.services.push_back(x.get());
  restart_ref.set_parts(std::move(parts));
}

}  // namespace partita::run
