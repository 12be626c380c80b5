#pragma once
// A service of a run: something the run does besides advancing its scheme (an audit, a CSV file,
// VTK output, restart files, the progress line, ...). It owns its state, answers to the window
// loop as an observer of each finished window (window_observer.hpp: in the order the run built
// the services, the initial state as window 0), and writes and reads its own section of a restart
// file. The loop calls, in this order:
//
//   serialize(ar)        writing a restart file: its section; resuming: its section read back
//                        (kept aside: nothing of the run changes before the whole file is read
//                        and accepted)
//   restored()           resuming, the whole file accepted: take what its section held (its
//                        files included)
//   start(resumed)       before the first observed window: create its files (their headers)
//   observe(w)           after each window (and for the initial state of a new run)
//   flush()              its files complete on disk (a flush service asks every few seconds)
//   finish(failed)       the run's end: close its files (failed: keep what is complete)
//   report(summary)      its share of the run's summary (also after a failure)
//   log_summary()        its line of the log after the run's summary line
//
// A service never writes another's state; what one needs of another (the balance audit's
// imbalances for coupling.csv, the monitors' values for the energy balance) it reads through that
// service's own const interface, given to it when the run is built.

#include <string>

#include "partita/coupling/window_observer.hpp"
#include "partita/interface/state_archive.hpp"

namespace partita::run {

struct RunSummary;

class Service : public coupling::WindowObserver {
 public:
  /// The name of its section in a restart file ("": it keeps nothing there).
  virtual std::string section() const { return {}; }
  /// Its section's contents, one function for writing and reading (StateArchive). Reading
  /// checks the values against the case and fails (ar.fail) at the first that does not fit.
  virtual void serialize(StateArchive& /*ar*/) {}
  /// A resumed run whose restart file has no section of this service (written by a run whose
  /// case did not have it): start afresh, or refuse (throw partita::Error naming `file`).
  virtual void without_section(const std::string& file);
  virtual void restored() {}
  virtual void start(bool /*resumed*/) {}
  virtual void flush() {}
  virtual void finish(bool /*failed*/) {}
  virtual void report(RunSummary& /*summary*/) const {}
  virtual void log_summary() const {}
};

}  // namespace partita::run
