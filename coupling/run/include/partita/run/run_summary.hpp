#pragma once
// What a run measured (CaseRun::summary()): the window loop's counts and times, and each
// service's share (Service::report).

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace partita::run {

/// What run() measured.
struct RunSummary {
  std::int64_t windows = 0;
  long iterations = 0;           ///< total over the windows
  long unconverged_windows = 0;  ///< accepted at max_iterations
  int max_window_iterations = 0;
  double wall_seconds = 0.0;
  std::vector<std::pair<std::string, double>> participant_seconds;
  double mapping_seconds = 0.0;
  double output_seconds = 0.0;         ///< VTK frames, restart files, CSV rows and flushes, and the
                                       ///< removal of an earlier run's VTK files from the folder
  /// Of the participants' seconds, those that passed while another participant of this process
  /// worked too (a parallel scheme on threads, coupling.concurrent): wall = participants -
  /// overlap + mapping + output + core.
  double overlap_seconds = 0.0;
  double core_seconds = 0.0;           ///< the rest: scheme, acceleration, time interpolation
  std::int64_t resumed_from = -1;      ///< windows done by the restart file resumed (-1: none)
  int stopped_by_signal = 0;           ///< the signal that stopped the run early (0: none)
  std::filesystem::path last_restart;  ///< the newest restart file written (empty: none)
  long imbalance_warnings = 0;         ///< windows where an exchange's balance exceeded the limit
  long energy_warnings = 0;            ///< windows where the coupling created too much energy
  long energy_balance_warnings = 0;    ///< windows with |energy balance error| over its bound
  /// The largest |energy balance error| of the windows whose energy reached energy.floor (the
  /// rule of energy.tolerance: EnergyBalance::counts), and when it occurred (-1: no window
  /// counted yet).
  double max_energy_balance_error = 0.0;
  double max_energy_balance_time = -1.0;
  std::int64_t max_energy_balance_window = -1;
  long energy_balance_uncounted = 0;  ///< windows below energy.floor (not counted)
  double mean_iterations() const {
    return windows > 0 ? static_cast<double>(iterations) / windows : 0.0;
  }
};

}  // namespace partita::run
