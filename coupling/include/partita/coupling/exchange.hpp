#pragma once
// One data field sent from a participant's mesh to another participant's mesh: the values the
// core holds between the two sides, and the mapping.
//
//   sender:   its window value (averaged or last over its substeps: the participant's side,
//             participant.hpp) arrives in combined(); an implicit scheme may replace it by an
//             accelerated value — sent();
//   mapping:  received = M sent (the mapper; identity when none) — transmit();
//   receiver: gets the window's start value d_n and the newest value d_{n+1} on its own mesh
//             (window_input()) and sees them in time as it subcycles (its side again). Where no
//             new value came yet (first participant of a serial scheme, parallel explicit
//             schemes) d_{n+1} = d_n.
//
// Call order per window: window_output() handed to the writer's run_window(); [remember_previous()
// per iteration]; set sent(); transmit(); window_input() handed to the reader's run_window();
// accept_window() once the window is accepted.
//
// Where the mapping runs (map_on, the case key): in one process the core maps every exchange
// (the same numbers either way). With participants in processes of their own the core (in the
// controller's process) still maps every exchange, since the checks, the audits, the interface
// output and the restart files read both sides; what changes is what travels to a receiver in
// another process: with map_on: receiver (the default) the sender's values, which the receiver's
// process maps with its own copy of the mapper (set_mapped_by_receiver()); with map_on: sender
// the mapped values. What a participant in another process writes travels as written.

#include <memory>
#include <string>

#include <Eigen/Core>

#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/interface/solver.hpp"

namespace partita {
class StateArchive;
}  // namespace partita

namespace partita::coupling {

/// Which participant's process maps an exchange (the case key map_on; see the file comment).
enum class MapOn { receiver, sender };

class Exchange {
 public:
  struct End {
    Participant* participant = nullptr;
    std::string mesh;
  };

  /// `mapper` already computed from the sender's to the receiver's mesh; nullptr = identity
  /// (the meshes must then have the same number of points).
  Exchange(std::string data, End from, End to, DataSpec spec, std::unique_ptr<Mapper> mapper,
           ReaderSees reader_sees = ReaderSees::linear,
           WriterCombines writer_combines = WriterCombines::average);

  const std::string& data() const { return data_; }
  Participant& from() const { return *from_.participant; }
  Participant& to() const { return *to_.participant; }
  const std::string& from_mesh() const { return from_.mesh; }
  const std::string& to_mesh() const { return to_.mesh; }
  const DataSpec& spec() const { return spec_; }
  ReaderSees reader_sees() const { return reader_sees_; }
  WriterCombines writer_combines() const { return writer_combines_; }
  MapOn map_on() const { return map_on_; }
  void set_map_on(MapOn side) { map_on_ = side; }
  /// The receiver's process maps what it reads (it runs in another process and map_on is
  /// receiver): window_input() then also names the sender's values of d_n and d_{n+1}, and
  /// accept_window() keeps a copy of the sender's values of d_n.
  void set_mapped_by_receiver(bool on) { mapped_by_receiver_ = on; }
  bool mapped_by_receiver() const { return mapped_by_receiver_; }
  const Mapper* mapper() const { return mapper_.get(); }
  /// The sender's and the receiver's interface meshes (fixed for the run, see Solver::meshes()).
  const Mesh& source_mesh() const { return *source_mesh_; }
  const Mesh& target_mesh() const { return *target_mesh_; }
  /// "'pressure' fluid.nodes -> solid.nodes" for messages.
  const std::string& label() const { return label_; }

  // --- sender side ------------------------------------------------------------------------
  /// What the writer's run_window() fills: combined() (the window's value over its substeps).
  WindowOutput window_output();
  const Eigen::MatrixXd& combined() const { return combined_is_sent_ ? sent_ : combined_; }
  /// The values that transmit() maps (combined, or an accelerated iterate).
  Eigen::MatrixXd& sent();
  const Eigen::MatrixXd& sent() const { return sent_; }
  /// sent = combined without a copy (the two arrays swap; combined() reads sent's until the
  /// next finish_collect(), or until sent() is written).
  void send_combined();
  /// previous = sent (the iterate the readers saw), before an iteration overwrites sent().
  void remember_previous() { previous_ = sent_; }
  const Eigen::MatrixXd& previous() const { return previous_; }

  /// received = M sent.
  void transmit();

  // --- receiver side ----------------------------------------------------------------------
  /// What the reader's run_window() sees: d_n and d_{n+1} on its mesh, and how.
  WindowInput window_input() const;
  /// The newest mapped value d_{n+1}.
  const Eigen::MatrixXd& received() const { return end_; }
  /// d_n = d_{n+1}: the window is accepted (no copy: start_ is taken from end_ by the next
  /// transmit(), which swaps the two before mapping into end_).
  void accept_window() {
    start_is_end_ = true;
    if (mapped_by_receiver_) {  // d_n's values before the mapping, for the receiver's process
      sent_start_ = sent_;
      sent_start_known_ = true;
    }
  }

  /// Initial data, once the writer's initial_values() filled window_output()'s combined:
  /// sent = previous = combined, transmitted, start = end.
  void initialize();

  /// Restart files, written and read by this one function: the values carried between
  /// windows (combined, sent, previous, start, end). Reading throws partita::Error if the
  /// stored values do not fit this exchange's meshes.
  void serialize(StateArchive& ar);

  /// Wall time spent mapping [s].
  double mapping_seconds() const { return mapping_seconds_; }

 private:
  std::string data_;
  End from_, to_;
  DataSpec spec_;
  std::unique_ptr<Mapper> mapper_;
  ReaderSees reader_sees_;
  WriterCombines writer_combines_;
  MapOn map_on_ = MapOn::receiver;
  bool mapped_by_receiver_ = false;
  Eigen::MatrixXd sent_start_;     // mapped_by_receiver_: sent when d_n was accepted
  bool sent_start_known_ = false;  // (not after a restart file: then d_n travels mapped)
  Eigen::Index from_points_ = 0;
  const Mesh* source_mesh_ = nullptr;
  const Mesh* target_mesh_ = nullptr;

  std::string label_;
  Eigen::MatrixXd combined_, sent_, previous_;
  bool combined_is_sent_ = false;  // after send_combined(): combined_'s own values are stale
  Eigen::MatrixXd start_, end_;
  bool start_is_end_ = false;  // d_n = d_{n+1}: start_'s own values are stale
  double mapping_seconds_ = 0.0;
};

}  // namespace partita::coupling
