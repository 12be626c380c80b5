#pragma once
// One data field sent from a participant's mesh to another participant's mesh, with what the
// core does in between:
//
//   sender:   writes once per substep; the window's value is the average over its m substeps
//             (f = 1/m Σ_k f_k, `average`) or the last substep's value (`last`) — combined();
//             an implicit scheme may replace it by an accelerated value — sent();
//   mapping:  received = M sent (the mapper; identity when none) — transmit();
//   receiver: at substep k of m it reads, for `linear`, d_n + (k/m) (d_{n+1} - d_n) between the
//             window's start value d_n and the newest value d_{n+1}; for `constant`, d_{n+1}.
//             Where no new value came yet (first participant of a serial scheme, parallel
//             explicit schemes) d_{n+1} = d_n and both give the start value.
//
// Call order per window: begin_collect(); collect() after each substep of the writer;
// finish_collect(); [remember_previous() per iteration]; set sent(); transmit();
// read_at() during the reader's substeps; accept_window() once the window is accepted.

#include <memory>
#include <string>

#include <Eigen/Core>

#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/interface/solver.hpp"

namespace partita {
class BinaryWriter;
class BinaryReader;
}  // namespace partita

namespace partita::coupling {

enum class ReaderSees { constant, linear };
enum class WriterCombines { average, last };

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
  const Mapper* mapper() const { return mapper_.get(); }
  /// The sender's and the receiver's interface meshes (fixed for the run, see Solver::meshes()).
  const Mesh& source_mesh() const { return *source_mesh_; }
  const Mesh& target_mesh() const { return *target_mesh_; }
  /// "pressure fluid.nodes -> solid.nodes" for messages.
  std::string label() const;

  // --- sender side ------------------------------------------------------------------------
  // Called every substep: no allocation once the arrays have their sizes (first window).
  void begin_collect();
  /// The writer's values after one substep (checked: points x components).
  void collect(const Eigen::MatrixXd& values);
  /// The same, taking `values`' storage where it would copy them (the first substep of an
  /// average, every substep of `last`): `values` then holds stale numbers, of the shape of an
  /// earlier substep or empty, for a writer whose next write() sets (and sizes) every value.
  void collect_taking(Eigen::MatrixXd& values);
  /// combined = average or last of the collected substeps.
  void finish_collect();
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
  /// The value the receiver sees after the fraction s = k/m of the window: received() itself
  /// where that is the value (no copy), else the interpolation written into `scratch`.
  const Eigen::MatrixXd& read_at(double fraction, Eigen::MatrixXd& scratch) const;
  /// The newest mapped value d_{n+1}.
  const Eigen::MatrixXd& received() const { return end_; }
  /// d_n = d_{n+1}: the window is accepted (no copy: start_ is taken from end_ by the next
  /// transmit(), which swaps the two before mapping into end_).
  void accept_window() { start_is_end_ = true; }

  /// Initial data: combined = sent = previous = initial, transmitted, start = end.
  void initialize(const Eigen::MatrixXd& initial);

  /// Restart files: the values carried between windows (sent, combined, previous, start, end).
  void write_state(BinaryWriter& out) const;
  /// Throws partita::Error if the stored values do not fit this exchange's meshes.
  void read_state(BinaryReader& in);

  /// Wall time spent mapping [s].
  double mapping_seconds() const { return mapping_seconds_; }

 private:
  void check_shape(const Eigen::MatrixXd& values, const char* what) const;

  std::string data_;
  End from_, to_;
  DataSpec spec_;
  std::unique_ptr<Mapper> mapper_;
  ReaderSees reader_sees_;
  WriterCombines writer_combines_;
  Eigen::Index from_points_ = 0;
  const Mesh* source_mesh_ = nullptr;
  const Mesh* target_mesh_ = nullptr;

  Eigen::MatrixXd accumulated_, combined_, sent_, previous_;
  bool combined_is_sent_ = false;  // after send_combined(): combined_'s own values are stale
  int collected_ = 0;
  Eigen::MatrixXd start_, end_;
  bool start_is_end_ = false;  // d_n = d_{n+1}: start_'s own values are stale
  double mapping_seconds_ = 0.0;
};

}  // namespace partita::coupling
