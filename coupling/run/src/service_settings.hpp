#pragma once
// What the services of a run are built from: each service's settings from the validated case and
// what it observes (case_run_services.cpp reads them, CaseRun::build_services() builds them).

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "partita/coupling/energy_balance.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/interface/vtk_xml.hpp"
#include "partita/run/case_run.hpp"
#include "services/energy_audit.hpp"
#include "services/monitors.hpp"
#include "services/restart_files.hpp"

namespace partita::run {

struct CaseRun::ServiceSettings {
  double output_every = 0.0;  // VTK frames (0: first and last only)
  vtk::Options vtk;           // output.vtk
  RestartFiles::Settings restart;
  // the balance audit: the exchanges audited and the relative imbalance that warns
  std::vector<const coupling::Exchange*> audited;
  double balance_tolerance = 0.01;
  // the energy audit: pairs of participants that read from each other
  std::vector<EnergyAudit::Pair> energy_pairs;
  double energy_tolerance = 0.5;  // created / passed that stops the run (or warns)
  bool energy_stop = true;
  std::vector<Monitors::Monitor> monitors;
  // the energy balance (null without an energy section) and its terms in its order
  std::unique_ptr<coupling::EnergyBalance> energy;
  std::vector<std::pair<coupling::Participant*, std::string>> energy_terms;
  int energy_every = 1;  // energy.every: the balance's row every this many windows
};

}  // namespace partita::run
