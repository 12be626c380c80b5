#pragma once
// A coupling scheme: how the participants take a time window together (template method: this
// base owns the flow of a window — subcycling one participant, accepting the window — and a
// scheme decides only the order, the iterations and what is sent when).
//
// Call order (CaseRun guarantees it):
//   initialize()                       — once: each exchange's writer gives its initial values
//   for windows n = 0, 1, ...: advance(window n)   — returns the window's report
//
// A participant takes a window on its side (participant.hpp: Algorithm 1 of seed 000, its
// substeps, the time interpolation of what it reads and the combination of what it writes):
// the scheme hands it each input's values at the window's ends and gets back each output's
// window value, one call per participant per window (per iteration when implicit).

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/coupling/time_window.hpp"

namespace partita::coupling {

struct WindowReport {
  int iterations = 1;             ///< times the participants ran the window
  bool converged = true;          ///< false if an implicit scheme stopped at max_iterations
  std::vector<double> residuals;  ///< one per residual_columns() entry (last iteration)
};

class CouplingScheme {
 public:
  /// Participants in scheme order; exchanges between them. Not owned.
  CouplingScheme(std::vector<Participant*> participants, std::vector<Exchange*> exchanges);
  virtual ~CouplingScheme();  // joins the participants' threads
  CouplingScheme(const CouplingScheme&) = delete;
  CouplingScheme& operator=(const CouplingScheme&) = delete;

  /// Initial data of every exchange: the writer's initial value before the first window, mapped.
  void initialize();
  /// Take every participant through `window` (substep counts are the participants' own) and
  /// accept it.
  WindowReport advance(const TimeWindow& window);

  /// Registered name.
  virtual std::string name() const = 0;
  /// True for a scheme whose participants take a window from the same inputs (they can run at
  /// the same time: explicit-parallel, implicit-parallel).
  virtual bool parallel() const { return false; }

  /// A parallel scheme runs the participants of this process at the same time, each on a
  /// thread of its own (participant_threads.hpp; the default), or one after the other (false).
  /// The results are the same bits either way. No effect on a serial scheme.
  void set_concurrent(bool concurrent) { concurrent_ = concurrent; }
  bool concurrent() const { return concurrent_; }
  /// Join the participants' threads (after the last window; the destructor does it too).
  void stop_threads();
  /// Seconds of the participants' own time (Participant::seconds()) that passed while another
  /// participant of this process worked too: the sum of the participants' seconds minus this
  /// is what they took of the wall time.
  double overlap_seconds() const { return overlap_seconds_; }
  /// OpenMP threads of each participant running at the same time (in scheme order among
  /// this process's participants; empty until a concurrent window ran; kept by stop_threads()).
  std::vector<int> concurrent_omp_threads() const;
  /// Columns (name, unit) of the per-window residuals in coupling.csv.
  virtual std::vector<std::pair<std::string, std::string>> residual_columns() const { return {}; }

  /// Restart files, between windows, written and read by this one function: every exchange's
  /// values, then what the scheme itself carries (an implicit scheme: its acceleration's
  /// history).
  virtual void serialize(StateArchive& ar);

  const std::vector<Participant*>& participants() const { return participants_; }
  const std::vector<Exchange*>& exchanges() const { return exchanges_; }

 protected:
  /// Run the window until it can be accepted (explicit: once; implicit: until converged).
  virtual WindowReport run_window(const TimeWindow& window) = 0;

  /// Participant p takes the window; its outputs' combined() values are set once
  /// p.finish_window() returns (a participant in another process works in the meantime).
  void run_participant(Participant& p, const TimeWindow& window);
  /// Every participant takes the window, at the same time where they can: the remote ones
  /// are started first, then those of this process, on threads where concurrent() (a parallel
  /// scheme); finish with send_outputs() or finish_window(). An error of a participant of this
  /// process names it (every one finishes the window first when they run at the same time).
  void run_all(const TimeWindow& window);
  /// Wait for p's window; sent = combined; transmit (for every output of p).
  void send_outputs(Participant& p);

  std::vector<Participant*> participants_;
  std::vector<Exchange*> exchanges_;

 private:
  // Participant i's inputs and outputs in slots_[i] (from the exchanges).
  void gather(std::size_t i);
  std::size_t index_of(const Participant& p) const;

  // What run_participant() hands over, per participant (sized once: no allocation per window).
  struct Slot {
    std::vector<WindowInput> inputs;
    std::vector<WindowOutput> outputs;
  };
  std::vector<Slot> slots_;
  bool concurrent_ = true;
  struct Threads;  // the participants' threads and their jobs (scheme/participant_threads.hpp)
  std::unique_ptr<Threads> threads_;  // made by the first concurrent window
  double overlap_seconds_ = 0.0;
};

}  // namespace partita::coupling
