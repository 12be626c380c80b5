// Restart files of format 5, written by earlier partita versions: the run's values in fixed
// places after the case (the loop's counters and the VTK frame count together, then sections
// "energy audit", "energy balance", "csv" and "vtk") rather than in each service's own section.
// Read here into the same services, each through its own serialise function (the VTK output's in
// its two parts), so a run written before the services had sections continues bit for bit.

#include "restart_file.hpp"
#include "services/energy_balance_service.hpp"
#include "services/vtk_output.hpp"

namespace partita::run {

namespace {

Service& service(RestartParts& parts, const std::string& section) {
  for (Service* s : parts.services)
    if (s->section() == section) return *s;
  throw Error("(internal) a run without its service '" + section + "'");
}

}  // namespace

void read_format5_sections(StateArchive& ar, RestartParts& parts) {
  RunState& run = *parts.run;
  auto& vtk = dynamic_cast<VtkOutput&>(service(parts, "vtk"));
  run.serialize_windows_done(ar);
  vtk.serialize_frames(ar);
  run.serialize_counters(ar);
  service(parts, "balance audit").serialize(ar);
  ar.section("energy audit");
  service(parts, "energy audit").serialize(ar);
  ar.section("energy balance");  // written also by runs without an energy section
  Service* energy = nullptr;
  for (Service* s : parts.services)
    if (s->section() == "energy balance") energy = s;
  if (energy)
    energy->serialize(ar);
  else
    EnergyBalanceService::skip(ar);
  ar.section("csv");
  service(parts, "coupling.csv").serialize(ar);
  service(parts, "monitors").serialize(ar);
  ar.section("vtk");
  vtk.serialize_series(ar);
}

}  // namespace partita::run
