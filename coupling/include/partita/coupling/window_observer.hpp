#pragma once
// What watches a run window by window. The run advances its scheme one window, then hands the
// finished window to each observer in the order it registered them; the initial state (after
// the scheme's initialisation, before the first window) is handed over as window 0. An observer
// may stop the run by throwing partita::Error (a diagnosis); the observers after it then do not
// see that window. The case runner's services observe its windows this way (partita::run,
// service.hpp), in their order: the balance audit, the divergence stop, coupling.csv, the
// monitors, the energy balance, the energy audit, the VTK output, the stop requests (signals),
// the restart files, the CSV flushes and the progress line.

#include <cstdint>

#include "partita/coupling/coupling_scheme.hpp"

namespace partita::coupling {

struct FinishedWindow {
  std::int64_t window = 0;               ///< windows done (0: the initial state)
  double time = 0.0;                     ///< its end [s]
  const WindowReport* report = nullptr;  ///< the scheme's report (nullptr: the initial state)
  bool last = false;                     ///< the case's last window
  /// A stop signal (SIGINT, SIGTERM) seen after this window: set by the observer that asks for
  /// stop requests, read by those after it (a restart file) and by the run (it ends there).
  int signal = 0;
  bool initial() const { return report == nullptr; }
};

class WindowObserver {
 public:
  virtual ~WindowObserver() = default;
  virtual void observe(FinishedWindow& w) = 0;
};

}  // namespace partita::coupling
