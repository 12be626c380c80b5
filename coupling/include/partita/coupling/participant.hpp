#pragma once
// A coupling participant: the seam between the core and one solver. The core hands a
// participant, once per window (per iteration of an implicit scheme), what it reads at the
// window's two ends, and gets back what it wrote, combined over its substeps. What happens in
// between is the participant's side:
//
//   for k = 0..m-1 (m substeps of its own, fixed or from its stable step):
//     read each input at the substep's end t_{n,k+1}:  d_n + ((k+1)/m) (d_{n+1} - d_n)
//       (`linear`), or d_{n+1} (`constant`); d_n where no new value came yet
//     advance(t_{n,k+1} - t_{n,k})
//     write each output f_{n,k+1}
//   each output's window value: 1/m sum_k f_{n,k} (`average`, the running mean) or f_{n,m} (`last`)
//
// The schemes and the run talk to participants only, never to a Solver: a participant in this
// process (LocalParticipant, over a Solver) and, later, one in another process (a proxy that
// sends the same window over MPI) are alike to them. The participant also answers for its
// solver between windows: checkpoints, monitors, the state check, interface work, output and
// restart data.
//
// Call order (the schemes and CaseRun guarantee it): initial_values() once; then per window
// [save_checkpoint()] run_window() [restore_checkpoint() and run_window() again]...; between
// windows the queries, write_output(), write_restart() / read_restart(); finalize() once.

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "partita/coupling/time_window.hpp"
#include "partita/interface/solver.hpp"

namespace partita::coupling {

/// How the reader sees a field between the window's ends.
enum class ReaderSees { constant, linear };
/// How the writer's substep values become the window's value.
enum class WriterCombines { average, last };

/// How a participant tiles a window: a fixed number of substeps, or `auto` (the fewest
/// substeps no longer than its stable_time_step()).
struct Substeps {
  bool automatic = false;
  int count = 1;
};

/// One field a participant receives in a window, on its own mesh (already mapped).
struct WindowInput {
  const std::string* mesh = nullptr;
  const std::string* data = nullptr;
  ReaderSees sees = ReaderSees::linear;
  const Eigen::MatrixXd* start = nullptr;  ///< d_n (not used when start_is_end)
  const Eigen::MatrixXd* end = nullptr;    ///< d_{n+1}, the newest value
  bool start_is_end = true;                ///< no new value this window: d_{n+1} = d_n
  /// Where the receiver's own process maps (map_on: receiver, the receiver in another process):
  /// the sender's values whose mapping d_n and d_{n+1} are (start and end above hold the mapped
  /// values as well; a port in another process sends these, the smaller message where the
  /// sender's mesh is the smaller). nullptr: not known (then the mapped value travels).
  const Eigen::MatrixXd* sent_start = nullptr;
  const Eigen::MatrixXd* sent_end = nullptr;
};

/// One field a participant sends: its window value goes to *combined (whose storage may be
/// exchanged with the participant's own buffers: no copy, no allocation after the first window).
struct WindowOutput {
  const std::string* mesh = nullptr;
  const std::string* data = nullptr;
  WriterCombines combines = WriterCombines::average;
  Eigen::Index points = 0;  ///< rows the writer must give (its mesh's points)
  int components = 1;       ///< columns
  const std::string* label = nullptr;  ///< the exchange, for messages
  Eigen::MatrixXd* combined = nullptr;
};

/// What the reader of `in` sees at `fraction` of the window (0: its start, 1: its end): the one
/// time interpolation of what a participant reads. d_{n+1} (`constant`, no new value this window,
/// fraction >= 1), else d_n + fraction (d_{n+1} - d_n) computed into `scratch` (`linear`).
/// Returns *in.end or scratch.
const Eigen::MatrixXd& input_at(const WindowInput& in, double fraction, Eigen::MatrixXd& scratch);

class Participant {
 public:
  explicit Participant(std::string name) : name_(std::move(name)) {}
  virtual ~Participant() = default;
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  const std::string& name() const { return name_; }

  /// The coupling meshes (fixed for the run, see Solver::meshes()).
  virtual const std::vector<InterfaceMesh>& meshes() const = 0;
  /// The interface mesh of that name, or nullptr.
  const InterfaceMesh* find_mesh(std::string_view mesh) const;

  /// The initial value of every output (the solver's write() before the first window).
  virtual void initial_values(std::span<WindowOutput> outputs) = 0;
  /// Take the window with its substeps: inputs read at each substep's end, outputs combined.
  /// `inputs` and `outputs` come in the same order every window.
  virtual void run_window(const TimeWindow& window, std::span<const WindowInput> inputs,
                          std::span<WindowOutput> outputs) = 0;
  /// Wait until the window of the last run_window() is done and its outputs are set (a
  /// participant in another process works while the caller goes on; in process: nothing).
  virtual void finish_window() {}
  /// A signal the participant's process received (0: none): the run stops after the window.
  virtual int stop_request() const { return 0; }
  /// The run stops after this window because of `signal` (a participant in another process
  /// then exits with 128 + signal, as this one does).
  virtual void note_stop(int /*signal*/) {}
  /// True for a participant that works in another process (a parallel scheme starts those
  /// first, then works on the ones in this process).
  virtual bool remote() const { return false; }
  /// What talking to it cost, for the run's summary ("": nothing to say, in process).
  virtual std::string transport_summary() const { return {}; }
  /// Substeps for a window of `window_size` (throws where a fixed count has become too coarse).
  virtual int substeps(double window_size) const = 0;
  virtual double stable_time_step() const = 0;

  virtual void save_checkpoint() = 0;
  virtual void restore_checkpoint() = 0;

  // Between windows: what the solver reports (Solver's contract).
  virtual std::vector<MonitorValue> monitors() const = 0;
  virtual std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const = 0;
  virtual std::string check_state() const = 0;
  virtual std::optional<double> interface_work(std::string_view mesh) const = 0;
  virtual void write_output(const OutputFrame& frame) = 0;
  virtual std::vector<std::pair<std::string, std::string>> output_files() const = 0;
  virtual bool supports_restart() const = 0;
  virtual void write_restart(BinaryWriter& out) const = 0;
  virtual void read_restart(BinaryReader& in) = 0;
  virtual void finalize() = 0;

  /// Wall time spent inside the solver's calls [s].
  double seconds() const { return seconds_; }
  void add_seconds(double s) { seconds_ += s; }

 private:
  std::string name_;
  double seconds_ = 0.0;
};

/// A participant in this process: a Solver, subcycled here.
class LocalParticipant final : public Participant {
 public:
  LocalParticipant(std::string name, std::unique_ptr<Solver> solver, Substeps substeps = {});

  Solver& solver() { return *solver_; }
  const Solver& solver() const { return *solver_; }
  const Substeps& substep_setting() const { return substeps_; }
  /// While run_window() runs (a solver's advance() may ask): the window with its substep count
  /// and the substeps done before the current one, and the window's inputs. nullptr and empty
  /// outside run_window(). (The external-code API reads at any time of a step through these.)
  const TimeWindow* current_window() const { return current_window_; }
  std::span<const WindowInput> current_inputs() const { return current_inputs_; }

  const std::vector<InterfaceMesh>& meshes() const override { return solver_->meshes(); }
  void initial_values(std::span<WindowOutput> outputs) override;
  void run_window(const TimeWindow& window, std::span<const WindowInput> inputs,
                  std::span<WindowOutput> outputs) override;
  int substeps(double window_size) const override;
  double stable_time_step() const override { return solver_->stable_time_step(); }
  void save_checkpoint() override;
  void restore_checkpoint() override;
  std::vector<MonitorValue> monitors() const override { return solver_->monitors(); }
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override {
    return solver_->monitor_values(names);
  }
  std::string check_state() const override { return solver_->check_state(); }
  std::optional<double> interface_work(std::string_view mesh) const override {
    return solver_->interface_work(mesh);
  }
  void write_output(const OutputFrame& frame) override { solver_->write_output(frame); }
  std::vector<std::pair<std::string, std::string>> output_files() const override {
    return solver_->output_files();
  }
  bool supports_restart() const override { return solver_->supports_restart(); }
  void write_restart(BinaryWriter& out) const override { solver_->write_restart(out); }
  void read_restart(BinaryReader& in) override { solver_->read_restart(in); }
  void finalize() override { solver_->finalize(); }

 private:
  // Per output: the solver's write buffer and the running combination (sized in the first
  // window, reused after: no allocation per substep).
  struct Collect {
    Eigen::MatrixXd written, accumulated;
    int count = 0;
  };
  void collect(const WindowOutput& o, Collect& c);
  std::unique_ptr<Solver> solver_;
  Substeps substeps_;
  std::vector<Collect> collect_;
  std::vector<Eigen::MatrixXd> read_scratch_;         // per input: the interpolated values
  std::vector<const Eigen::MatrixXd*> read_values_;   // per input: what the solver reads
  const TimeWindow* current_window_ = nullptr;
  std::span<const WindowInput> current_inputs_;
};

}  // namespace partita::coupling
