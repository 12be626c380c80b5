#pragma once
// The messages between the controller's proxy of a participant in another process
// (RemoteParticipant) and that process's request loop (ParticipantServer): the commands and the
// write/read function pairs of what they carry (meshes, monitor values, outputs). The byte
// layouts are the shared codec's (interface binary_io.hpp).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/binary_io.hpp"
#include "partita/run/remote_participant.hpp"

namespace partita::run::remote {

using namespace coupling;  // the core this library builds on

enum class Command : std::uint32_t {
  initial_values = 1,
  run_window,
  save_checkpoint,
  restore_checkpoint,
  monitors,
  monitor_values,
  check_state,
  interface_work,
  write_output,
  output_files,
  write_restart,
  read_restart,
  substeps,
  stable_time_step,
  finalize,
  abort,
  meshes,   // handshake: the meshes a server asked for
  mapping,  // before the first window: an exchange the server maps on its side
};

// Whether two matrices hold the same values to the bit (-0 and 0 differ, a NaN equals its copy).
bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
// Starts a message in `buffer` (cleared: its capacity is kept) with its command.
MessageWriter start(std::string& buffer, Command c);
void write_mesh(MessageWriter& out, const InterfaceMesh& m);
InterfaceMesh read_mesh(MessageReader& in);
void write_monitors(MessageWriter& out, const std::vector<MonitorValue>& v);
// Into `v`, reusing its storage (no allocation for the same names as the last time).
void read_monitors(MessageReader& in, std::vector<MonitorValue>& v);
void write_strings(MessageWriter& out, const std::vector<std::string>& v);
// Into `v`, reusing its storage.
void read_strings(MessageReader& in, std::vector<std::string>& v);
// What a participant writes (its outputs' names, shapes and combination), in requests.
void write_outputs(MessageWriter& out, std::span<const WindowOutput> outputs);

// The server's side of write_outputs(): the descriptors with their names and value storage,
// kept between requests (no allocation once the shapes are known).
struct OutputSlots {
  std::vector<std::string> names;  // mesh, data, label per output
  std::vector<Eigen::MatrixXd> combined;
  std::vector<WindowOutput> outputs;
  void read(MessageReader& in);
};

}  // namespace partita::run::remote
