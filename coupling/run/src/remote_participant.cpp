// A participant in another process, the controller's side: its proxy (RemoteParticipant) and the
// start-up handshake. The remote side's request loop is participant_server.cpp; the messages are
// written and read by one function pair each (remote_messages.hpp).
#include "partita/run/remote_participant.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>  // restart data only (a solver writes it to a BinaryWriter)

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/version.hpp"
#include "remote_messages.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on
using namespace remote;    // the messages

std::uint64_t case_hash(const config::Node& loaded) {
  YAML::Emitter e;
  e << loaded.yaml();
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : std::string(e.c_str())) h = (h ^ c) * 1099511628211ull;
  return h;
}

// ---------------------------------------------------------------------------------------------
// The controller's side

RemoteParticipant::RemoteParticipant(std::string name, Channel& channel, Ready ready)
    : Participant(std::move(name)),
      channel_(channel),
      peer_(channel.peer()),
      meshes_(std::move(ready.meshes)),
      supports_restart_(ready.supports_restart),
      maps_inputs_(ready.maps_inputs) {}

std::string_view RemoteParticipant::read_reply(std::string_view what) const {
  Stopwatch wait;
  channel_.receive(reply_, what);
  wait_seconds_ += wait.seconds();
  ++messages_;
  bytes_received_ += static_cast<double>(reply_.size());
  // [u32 status] [results | error text] [f64 seconds] [i32 signal]: the results are read in
  // place, the rest too
  constexpr std::size_t head = sizeof(std::uint32_t), tail = sizeof(double) + sizeof(std::int32_t);
  if (reply_.size() < head) throw Error(peer_ + " sent a damaged reply");
  std::uint32_t status = 0;
  std::memcpy(&status, reply_.data(), head);
  if (status != 0) {
    MessageReader r(std::string_view(reply_).substr(head), peer_);
    throw Error(fmt::format("{} failed: {}", peer_, r.view_string()));
  }
  if (reply_.size() < head + tail) throw Error(peer_ + " sent a damaged reply");
  double seconds = 0.0;
  std::int32_t signal = 0;
  std::memcpy(&seconds, reply_.data() + reply_.size() - tail, sizeof(double));
  std::memcpy(&signal, reply_.data() + reply_.size() - sizeof(std::int32_t), sizeof(std::int32_t));
  extra_seconds_ += seconds;
  if (signal != 0) stop_request_ = signal;
  return std::string_view(reply_).substr(head, reply_.size() - head - tail);
}

std::string_view RemoteParticipant::call(std::string_view what) const {
  Stopwatch send;
  bytes_sent_ += static_cast<double>(request_.size());
  channel_.send(request_);
  wait_seconds_ += send.seconds();
  const std::string_view reply = read_reply(what);
  const_cast<RemoteParticipant*>(this)->add_seconds(extra_seconds_);
  extra_seconds_ = 0.0;
  return reply;
}

void RemoteParticipant::initial_values(std::span<WindowOutput> outputs) {
  MessageWriter out = start(request_, Command::initial_values);
  write_outputs(out, outputs);
  MessageReader r(call("its initial values"), peer_);
  for (WindowOutput& o : outputs) r.read(*o.combined);
}

void RemoteParticipant::run_window(const TimeWindow& window, std::span<const WindowInput> inputs,
                                   std::span<WindowOutput> outputs) {
  if (pending_window_) finish_window();
  MessageWriter out = start(request_, Command::run_window);
  out.write(window.size());
  out.write(static_cast<std::int64_t>(window.index()));
  out.write(static_cast<std::uint64_t>(inputs.size()));
  if (held_.size() != inputs.size()) held_.assign(inputs.size(), Held{});
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const WindowInput& in = inputs[i];
    Held& held = held_[i];
    if (held.mesh != in.mesh || held.data != in.data) {  // another input: nothing held
      held = Held{};
      held.mesh = in.mesh;
      held.data = in.data;
    }
    out.write(*in.mesh);
    out.write(*in.data);
    out.write(static_cast<std::uint8_t>(in.sees == ReaderSees::linear));
    out.write(static_cast<std::uint8_t>(in.start_is_end));
    // [u8 flags] which travel as the sender's values, the server maps them: 1 end, 2 start;
    // the start does not travel: 4 it is the last request's end, 8 its start
    const bool start = !in.start_is_end && in.sees == ReaderSees::linear;
    const bool start_unmapped = start && in.sent_start;
    const Eigen::MatrixXd& start_values = start_unmapped ? *in.sent_start : *in.start;
    std::uint8_t flags = (in.sent_end ? 1 : 0) | (start_unmapped ? 2 : 0);
    if (start && held.end_valid && held.end_unmapped == start_unmapped &&
        same_bits(held.end, start_values))
      flags |= 4;  // the next window: d_n = the last d_{n+1}
    else if (start && held.start_valid && held.start_unmapped == start_unmapped &&
             same_bits(held.start, start_values))
      flags |= 8;  // the next iteration: the same d_n
    out.write(flags);
    if (start && !(flags & 12)) out.write(start_values);
    const Eigen::MatrixXd& end_values = flags & 1 ? *in.sent_end : *in.end;
    out.write(end_values);
    // what the server holds now (as it will do: a start taken from the last end swaps the two)
    if (flags & 4) held.start.swap(held.end);
    else if (start && !(flags & 8)) held.start = start_values;  // (no allocation: same shape)
    held.start_valid = start;
    held.start_unmapped = start_unmapped;
    held.end = end_values;
    held.end_valid = true;
    held.end_unmapped = flags & 1;
  }
  write_outputs(out, outputs);
  // What the run asks after a window, answered with the window's reply (one message each way
  // per window): the monitors, the state check and the interface work it asked for before.
  write_strings(out, cache_.monitor_names);
  out.write(static_cast<std::uint8_t>(cache_.want_state));
  write_strings(out, cache_.work_meshes);
  cache_.valid = false;
  Stopwatch send;
  bytes_sent_ += static_cast<double>(request_.size());
  channel_.send(request_);
  // the peer waits for it: let it start while this process runs its own participants
  channel_.deliver("the window's inputs to be taken");
  wait_seconds_ += send.seconds();
  pending_.assign(outputs.begin(), outputs.end());  // (no allocation after the first window)
  pending_window_ = true;
}

void RemoteParticipant::finish_window() {
  if (!pending_window_) return;
  pending_window_ = false;
  MessageReader r(read_reply("the end of its window"), peer_);
  add_seconds(extra_seconds_);
  extra_seconds_ = 0.0;
  for (WindowOutput& o : pending_) r.read(*o.combined);
  read_monitors(r, cache_.monitors);
  if (cache_.want_state) r.read(cache_.state);
  cache_.work.clear();
  for (std::size_t i = 0; i < cache_.work_meshes.size(); ++i) {
    if (r.get<std::uint8_t>() != 0)
      cache_.work.emplace_back(r.get<double>());
    else
      cache_.work.emplace_back(std::nullopt);
  }
  cache_.valid = true;
}

std::string RemoteParticipant::transport_summary() const {
  // the remote solver's own time is in seconds(); the rest of the waits is the messages' way
  // there and back (and the remote side's decoding and encoding)
  return fmt::format(
      "{} replies from {}, {:.3f} s waiting for them (its solver {:.3f} s of it); {:.1f} kB sent "
      "to it, {:.1f} kB received",
      messages_, peer_, wait_seconds_, seconds(), bytes_sent_ / 1e3, bytes_received_ / 1e3);
}

void RemoteParticipant::prepare_mapping(std::size_t exchange, const std::string& mesh,
                                        const std::string& data, const InterfaceMesh& sender) {
  MessageWriter out = start(request_, Command::mapping);
  out.write(static_cast<std::uint64_t>(exchange));
  out.write(mesh);
  out.write(data);
  write_mesh(out, sender);
  call("the set-up of the mapping of '" + data + "' to its mesh '" + mesh + "'");
}

int RemoteParticipant::substeps(double window_size) const {
  MessageWriter out = start(request_, Command::substeps);
  out.write(window_size);
  MessageReader r(call("its substeps"), peer_);
  return r.get<std::int32_t>();
}

double RemoteParticipant::stable_time_step() const {
  start(request_, Command::stable_time_step);
  MessageReader r(call("its stable time step"), peer_);
  return r.get<double>();
}

void RemoteParticipant::save_checkpoint() {
  start(request_, Command::save_checkpoint);
  call("its checkpoint");
}

void RemoteParticipant::restore_checkpoint() {
  cache_.valid = false;
  start(request_, Command::restore_checkpoint);
  call("the restoring of its checkpoint");
}

std::vector<MonitorValue> RemoteParticipant::monitors() const {
  start(request_, Command::monitors);
  MessageReader r(call("its monitors"), peer_);
  std::vector<MonitorValue> v;
  read_monitors(r, v);
  return v;
}

std::vector<MonitorValue> RemoteParticipant::monitor_values(
    const std::vector<std::string>& names) const {
  if (cache_.valid && names == cache_.monitor_names) return cache_.monitors;
  cache_.monitor_names = names;  // asked with every window from now on
  MessageWriter out = start(request_, Command::monitor_values);
  write_strings(out, names);
  MessageReader r(call("its monitor values"), peer_);
  std::vector<MonitorValue> v;
  read_monitors(r, v);
  return v;
}

std::string RemoteParticipant::check_state() const {
  if (cache_.valid && cache_.want_state) return cache_.state;
  cache_.want_state = true;
  start(request_, Command::check_state);
  MessageReader r(call("its state check"), peer_);
  return r.get_string();
}

std::optional<double> RemoteParticipant::interface_work(std::string_view mesh) const {
  const auto at = std::find(cache_.work_meshes.begin(), cache_.work_meshes.end(), mesh);
  if (cache_.valid && at != cache_.work_meshes.end())
    return cache_.work[static_cast<std::size_t>(at - cache_.work_meshes.begin())];
  if (at == cache_.work_meshes.end()) {
    cache_.work_meshes.emplace_back(mesh);
    cache_.valid = false;  // the cached answers no longer line up with the meshes
  }
  MessageWriter out = start(request_, Command::interface_work);
  out.write(mesh);
  MessageReader r(call("its interface work"), peer_);
  if (r.get<std::uint8_t>() == 0) return std::nullopt;
  return r.get<double>();
}

void RemoteParticipant::write_output(const OutputFrame& frame) {
  MessageWriter out = start(request_, Command::write_output);
  out.write(frame.vtk_directory.string());
  out.write(frame.prefix);
  out.write(static_cast<std::int32_t>(frame.index));
  out.write(frame.time);
  out.write(static_cast<std::int32_t>(frame.vtk.format));
  out.write(static_cast<std::int32_t>(frame.vtk.zlib_level));
  out.write(static_cast<std::uint64_t>(frame.vtk.block_size));
  out.write(static_cast<std::int32_t>(frame.vtk.precision));
  call("its output");
}

std::vector<std::pair<std::string, std::string>> RemoteParticipant::output_files() const {
  start(request_, Command::output_files);
  MessageReader r(call("its output files"), peer_);
  std::vector<std::string> a, b;
  read_strings(r, a);
  read_strings(r, b);
  std::vector<std::pair<std::string, std::string>> files;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) files.emplace_back(a[i], b[i]);
  return files;
}

void RemoteParticipant::write_restart(BinaryWriter& out) const {
  start(request_, Command::write_restart);
  MessageReader r(call("its restart data"), peer_);
  BinaryWriter::Recording rec;
  rec.header = r.get_string();
  const auto n = r.count(2 * sizeof(std::uint64_t), "a list of restart sections");
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string name = r.get_string();
    rec.sections.emplace_back(std::move(name), r.get_string());
  }
  out.replay(rec);
}

void RemoteParticipant::read_restart(BinaryReader& in) {
  // this participant's part: up to the next part of the run's file
  const std::string part = in.raw_until([](const std::string& section) {
    return section.rfind("participant ", 0) == 0 || section == "end";
  });
  cache_.valid = false;
  MessageWriter out = start(request_, Command::read_restart);
  out.write(in.source());
  out.write(part);
  call("the reading of its restart data");
}

void RemoteParticipant::finalize() {
  MessageWriter out = start(request_, Command::finalize);
  out.write(static_cast<std::int32_t>(stop_request_));
  call("its finalize");
}

// ---------------------------------------------------------------------------------------------
// The handshake

Hello receive_hello(Channel& server, const std::string& participant, std::uint64_t case_hash) {
  const std::string peer = server.peer(), bytes = server.receive("its start-up message (hello)");
  MessageReader r(bytes, peer);
  Hello h;
  h.error = r.get_string();
  if (!h.error.empty())
    throw Error(fmt::format("{} failed at set-up: {}", peer, h.error));
  h.version = r.get_string();
  h.case_hash = r.get<std::uint64_t>();
  h.participant = r.get_string();
  h.program = r.get_string();
  std::string mismatch;
  if (h.version != std::string(version()))
    mismatch = fmt::format("it runs partita {}, this process {}", h.version, std::string(version()));
  else if (h.participant != participant)
    mismatch = fmt::format("it runs participant '{}', expected '{}'", h.participant, participant);
  else if (h.case_hash != case_hash)
    mismatch = fmt::format(
        "its case differs from this process's (case hash {:016x} against {:016x}): every process "
        "must read the same case file with the same --set options",
        h.case_hash, case_hash);
  if (!mismatch.empty()) {
    const std::string why = fmt::format("{} does not match the controller: {}", peer, mismatch);
    abort_server(server, why);
    throw Error(why);
  }
  const auto n = r.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) h.meshes.push_back(read_mesh(r));
  const auto q = r.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < q; ++i) {
    std::string name = r.get_string();
    h.mesh_requests.emplace_back(std::move(name), r.get_string());
  }
  return h;
}

Ready complete_handshake(Channel& server,
                         const std::vector<std::pair<std::string, Mesh>>& meshes) {
  std::string bytes;
  MessageWriter out = start(bytes, Command::meshes);
  out.write(static_cast<std::uint64_t>(meshes.size()));
  for (const auto& [name, mesh] : meshes) {
    out.write(name);
    write_mesh(out, InterfaceMesh{mesh, {}, {}});
  }
  server.send(bytes);
  const std::string peer = server.peer();
  server.receive(bytes, "its meshes after the handshake");
  MessageReader r(bytes, peer);
  Ready ready;
  ready.error = r.get_string();
  if (!ready.error.empty())
    throw Error(fmt::format("{} failed at set-up: {}", peer, ready.error));
  const auto n = r.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) ready.meshes.push_back(read_mesh(r));
  ready.supports_restart = r.get<std::uint8_t>() != 0;
  ready.stable_time_step = r.get<double>();
  ready.maps_inputs = r.get<std::uint8_t>() != 0;
  return ready;
}

void abort_server(Channel& server, const std::string& why) noexcept {
  try {
    std::string bytes;
    start(bytes, Command::abort).write(why);
    server.send(bytes);
  } catch (...) {
  }
}

}  // namespace partita::run
