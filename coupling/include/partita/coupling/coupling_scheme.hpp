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
  virtual ~CouplingScheme() = default;

  /// Initial data of every exchange: the writer's initial value before the first window, mapped.
  void initialize();
  /// Take every participant through `window` (substep counts are the participants' own) and
  /// accept it.
  WindowReport advance(const TimeWindow& window);

  /// Registered name.
  virtual std::string name() const = 0;
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
  /// are started first (a parallel scheme); finish with send_outputs() or finish_window().
  void run_all(const TimeWindow& window);
  /// Wait for p's window; sent = combined; transmit (for every output of p).
  void send_outputs(Participant& p);

  std::vector<Participant*> participants_;
  std::vector<Exchange*> exchanges_;

 private:
  // What run_participant() hands over (sized once: no allocation per window).
  std::vector<WindowInput> inputs_;
  std::vector<WindowOutput> outputs_;
};

}  // namespace partita::coupling
