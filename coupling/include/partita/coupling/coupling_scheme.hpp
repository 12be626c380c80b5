#pragma once
// A coupling scheme: how the participants take a time window together (template method: this
// base owns the flow of a window — subcycling one participant, accepting the window — and a
// scheme decides only the order, the iterations and what is sent when).
//
// Call order (CaseRun guarantees it):
//   initialize()                       — once: each exchange's writer gives its initial values
//   for windows n = 0, 1, ...: advance(window n)   — returns the window's report
//
// Subcycling a participant through a window of m substeps (Algorithm 1 of seed 000):
//   for k = 0..m-1:  read each input at the substep's end, t_{n,k+1} (time interpolation by
//                    the exchange), advance(t_{n,k+1} - t_{n,k}), write each output (collected)
//   each output's window value = average (or last) of its m substep values.

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

  /// Initial data of every exchange: the writer's write() before the first window, mapped.
  void initialize();
  /// Take every participant through `window` (substep counts are the participants' own) and
  /// accept it.
  WindowReport advance(const TimeWindow& window);

  /// Registered name.
  virtual std::string name() const = 0;
  /// Columns (name, unit) of the per-window residuals in coupling.csv.
  virtual std::vector<std::pair<std::string, std::string>> residual_columns() const { return {}; }

  /// Restart files, between windows: every exchange's values, then what the scheme itself
  /// carries (an implicit scheme: its acceleration's history).
  virtual void write_state(BinaryWriter& out) const;
  virtual void read_state(BinaryReader& in);

  const std::vector<Participant*>& participants() const { return participants_; }
  const std::vector<Exchange*>& exchanges() const { return exchanges_; }

 protected:
  /// Run the window until it can be accepted (explicit: once; implicit: until converged).
  virtual WindowReport run_window(const TimeWindow& window) = 0;

  /// Subcycle participant p through the window; its outputs' combined() values are then set.
  void run_participant(Participant& p, const TimeWindow& window);
  /// sent = combined; transmit (for every output of p).
  void send_outputs(const Participant& p);

  std::vector<Participant*> participants_;
  std::vector<Exchange*> exchanges_;

 private:
  // Per exchange: what its receiver reads and what its sender writes (sized in the first
  // window, reused after: no allocation per substep).
  std::vector<Eigen::MatrixXd> read_buffers_, write_buffers_;
  std::vector<const Eigen::MatrixXd*> inputs_;  // per exchange: what its reader sees this substep
};

}  // namespace partita::coupling
