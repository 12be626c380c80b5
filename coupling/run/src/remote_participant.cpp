// A participant in another process: the controller's proxy (RemoteParticipant), the remote
// side's request loop (ParticipantServer) and the start-up handshake. The message layouts are
// in remote_participant.hpp; each is written and read by one function pair here.
#include "partita/run/remote_participant.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>  // restart data only (a solver writes it to a BinaryWriter)

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/version.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace {

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
bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), static_cast<std::size_t>(a.size()) * sizeof(double)) == 0);
}

// Starts a message in `buffer` (cleared: its capacity is kept) with its command.
MessageWriter start(std::string& buffer, Command c) {
  buffer.clear();
  MessageWriter out(buffer);
  out.write(static_cast<std::uint32_t>(c));
  return out;
}

void write_mesh(MessageWriter& out, const InterfaceMesh& m) {
  out.write(m.mesh.name());
  out.write(Eigen::MatrixXd(m.mesh.points()));
  std::vector<int> tri(m.mesh.triangles().data(),
                       m.mesh.triangles().data() + m.mesh.triangles().size());
  out.write(tri);
  out.write(m.mesh.weights());
  out.write(static_cast<std::uint8_t>(m.prescribed));
  for (const auto* specs : {&m.reads, &m.writes}) {
    out.write(static_cast<std::uint64_t>(specs->size()));
    for (const DataSpec& d : *specs) {
      out.write(d.name);
      out.write(static_cast<std::int32_t>(d.components));
      out.write(d.unit);
      out.write(static_cast<std::int32_t>(d.kind));
    }
  }
}

InterfaceMesh read_mesh(MessageReader& in) {
  InterfaceMesh m;
  const std::string name = in.get_string();
  Eigen::MatrixXd points;
  in.read(points);
  std::vector<int> tri;
  in.read(tri);
  if (points.cols() != 3 || tri.size() % 3 != 0) in.fail("a mesh (points x 3, triangles x 3)");
  Mesh::Triangles t(static_cast<Eigen::Index>(tri.size() / 3), 3);
  std::copy(tri.begin(), tri.end(), t.data());
  m.mesh = Mesh(name, points, t);
  Eigen::VectorXd weights;
  in.read(weights);
  if (weights.size() > 0) m.mesh.set_weights(weights);
  m.prescribed = in.get<std::uint8_t>() != 0;
  for (auto* specs : {&m.reads, &m.writes}) {
    const auto n = in.get<std::uint64_t>();
    for (std::uint64_t i = 0; i < n; ++i) {
      DataSpec d;
      d.name = in.get_string();
      d.components = in.get<std::int32_t>();
      d.unit = in.get_string();
      d.kind = static_cast<DataKind>(in.get<std::int32_t>());
      specs->push_back(d);
    }
  }
  return m;
}

void write_monitors(MessageWriter& out, const std::vector<MonitorValue>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& m : v) {
    out.write(m.name);
    out.write(m.unit);
    out.write(m.value);
  }
}

// Into `v`, reusing its storage (no allocation for the same names as the last time).
void read_monitors(MessageReader& in, std::vector<MonitorValue>& v) {
  // an item: two counts and a value
  v.resize(in.count(3 * sizeof(std::uint64_t), "a list of monitor values"));
  for (auto& m : v) {
    in.read(m.name);
    in.read(m.unit);
    in.read(m.value);
  }
}

void write_strings(MessageWriter& out, const std::vector<std::string>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& s : v) out.write(s);
}

// What a participant writes (its outputs' names, shapes and combination), in requests.
void write_outputs(MessageWriter& out, std::span<const WindowOutput> outputs) {
  out.write(static_cast<std::uint64_t>(outputs.size()));
  for (const WindowOutput& o : outputs) {
    out.write(*o.mesh);
    out.write(*o.data);
    out.write(static_cast<std::uint8_t>(o.combines == WriterCombines::average));
    out.write(static_cast<std::int64_t>(o.points));
    out.write(static_cast<std::int32_t>(o.components));
    out.write(*o.label);
  }
}

// The server's side of write_outputs(): the descriptors with their names and value storage,
// kept between requests (no allocation once the shapes are known).
struct OutputSlots {
  std::vector<std::string> names;  // mesh, data, label per output
  std::vector<Eigen::MatrixXd> combined;
  std::vector<WindowOutput> outputs;
  void read(MessageReader& in) {
    const std::size_t n = in.count(3 * sizeof(std::uint64_t), "a list of outputs");
    names.resize(3 * n);
    combined.resize(n);
    outputs.assign(n, {});
    for (std::size_t i = 0; i < n; ++i) {
      WindowOutput& o = outputs[i];
      in.read(names[3 * i]);
      in.read(names[3 * i + 1]);
      o.combines = in.get<std::uint8_t>() ? WriterCombines::average : WriterCombines::last;
      o.points = in.get<std::int64_t>();
      o.components = in.get<std::int32_t>();
      in.read(names[3 * i + 2]);
    }
    for (std::size_t i = 0; i < n; ++i) {  // (names is sized: the pointers stay valid)
      outputs[i].mesh = &names[3 * i];
      outputs[i].data = &names[3 * i + 1];
      outputs[i].label = &names[3 * i + 2];
      outputs[i].combined = &combined[i];
    }
  }
};

// Into `v`, reusing its storage.
void read_strings(MessageReader& in, std::vector<std::string>& v) {
  v.resize(in.count(sizeof(std::uint64_t), "a list of texts"));
  for (auto& s : v) in.read(s);
}

}  // namespace

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

// ---------------------------------------------------------------------------------------------
// The remote side

ParticipantServer::ParticipantServer(Channel& controller, const std::atomic<int>* stop_signal)
    : controller_(controller), stop_signal_(stop_signal) {}

void ParticipantServer::fail_setup(const std::string& error) noexcept {
  try {
    std::string bytes;
    MessageWriter(bytes).write(error.empty() ? std::string("(no message)") : error);
    controller_.send(bytes);
  } catch (...) {
  }
}

std::vector<std::pair<std::string, Mesh>> ParticipantServer::hello(const Hello& h) {
  std::string bytes;
  {
    MessageWriter out(bytes);
    out.write(std::string());  // no error
    out.write(std::string(version()));
    out.write(h.case_hash);
    out.write(h.participant);
    out.write(h.program);
    out.write(static_cast<std::uint64_t>(h.meshes.size()));
    for (const auto& mesh : h.meshes) write_mesh(out, mesh);
    out.write(static_cast<std::uint64_t>(h.mesh_requests.size()));
    for (const auto& [name, source] : h.mesh_requests) {
      out.write(name);
      out.write(source);
    }
    controller_.send(bytes);
  }
  const std::string peer = controller_.peer();
  controller_.receive(bytes, "the meshes of the handshake");
  MessageReader r(bytes, peer);
  const auto c = static_cast<Command>(r.get<std::uint32_t>());
  if (c == Command::abort) throw StoppedByController("stopping: " + r.get_string());
  if (c != Command::meshes) throw Error("the controller sent a damaged handshake");
  std::vector<std::pair<std::string, Mesh>> got;
  const auto n = r.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string name = r.get_string();
    got.emplace_back(std::move(name), read_mesh(r).mesh);
  }
  return got;
}

int ParticipantServer::serve(LocalParticipant& p, const MappingFactory& mapping) {
  const std::string peer = controller_.peer();
  // The messages' buffers, kept for the whole run (they grow to the largest message; no
  // allocation after that).
  std::string request, reply;
  {
    MessageWriter out(reply);
    out.write(std::string());
    out.write(static_cast<std::uint64_t>(p.meshes().size()));
    for (const auto& mesh : p.meshes()) write_mesh(out, mesh);
    out.write(static_cast<std::uint8_t>(p.supports_restart()));
    out.write(p.stable_time_step());
    out.write(static_cast<std::uint8_t>(static_cast<bool>(mapping)));
    controller_.send(reply);
  }
  // What run_window() hands the participant, kept between windows (no allocation after the
  // first window).
  std::vector<std::string> names;  // mesh, data per input
  std::vector<Eigen::MatrixXd> starts, ends;
  std::vector<WindowInput> inputs;
  std::vector<std::string> monitor_names, work_meshes;
  // The exchanges this process maps (map_on: receiver), by mesh and data; the sender's values
  // as they arrive.
  struct Mapped {
    std::string mesh, data;
    ServerMapping mapping;
  };
  std::vector<Mapped> mapped;
  Eigen::MatrixXd unmapped_values;
  const auto map_into = [&](const std::string& mesh, const std::string& data,
                            Eigen::MatrixXd& out) {
    const auto at = std::find_if(mapped.begin(), mapped.end(), [&](const Mapped& x) {
      return x.mesh == mesh && x.data == data;
    });
    if (at == mapped.end())
      throw Error(fmt::format("the controller sent '{}' on '{}' to be mapped here, but set up no "
                              "mapping for it",
                              data, mesh));
    Stopwatch clock;
    at->mapping.mapper->map(unmapped_values, out);  // d = M s, as the controller's transmit()
    mapping_seconds_ += clock.seconds();
  };
  OutputSlots slots;
  double reported_seconds = 0.0;
  int stopped_by = 0;
  for (;;) {
    controller_.receive(request, "its next request");
    MessageReader r(request, peer);
    const auto command = static_cast<Command>(r.get<std::uint32_t>());
    if (command == Command::abort)
      throw StoppedByController("stopping: " + r.get_string());
    reply.clear();
    MessageWriter out(reply);
    out.write(std::uint32_t{0});
    bool done = false;
    try {
      switch (command) {
        case Command::initial_values: {
          slots.read(r);
          p.initial_values(slots.outputs);
          for (const auto& c : slots.combined) out.write(c);
          break;
        }
        case Command::run_window: {
          const double size = r.get<double>();
          const auto index = r.get<std::int64_t>();
          // an input: two names' counts, three flags and a matrix's shape at least
          const std::size_t ni = r.count(5 * sizeof(std::uint64_t), "a list of inputs");
          const std::size_t held = ni == starts.size() ? ni : 0;  // the last request's values
          names.resize(2 * ni);
          starts.resize(ni);
          ends.resize(ni);
          inputs.assign(ni, {});
          for (std::size_t i = 0; i < ni; ++i) {
            r.read(names[2 * i]);
            r.read(names[2 * i + 1]);
            inputs[i].sees = r.get<std::uint8_t>() ? ReaderSees::linear : ReaderSees::constant;
            inputs[i].start_is_end = r.get<std::uint8_t>() != 0;
            const auto unmapped = r.get<std::uint8_t>();
            if ((unmapped & 12) && i >= held) r.fail("values of the last request");
            if (unmapped & 4) {
              starts[i].swap(ends[i]);  // d_n: the last request's d_{n+1}
            } else if (unmapped & 8) {
              // d_n: the last request's
            } else if (!inputs[i].start_is_end && inputs[i].sees == ReaderSees::linear) {
              if (unmapped & 2) {
                r.read(unmapped_values);
                map_into(names[2 * i], names[2 * i + 1], starts[i]);
              } else {
                r.read(starts[i]);
              }
            }
            if (unmapped & 1) {
              r.read(unmapped_values);
              map_into(names[2 * i], names[2 * i + 1], ends[i]);
            } else {
              r.read(ends[i]);
            }
          }
          slots.read(r);
          for (std::size_t i = 0; i < ni; ++i) {
            inputs[i].mesh = &names[2 * i];
            inputs[i].data = &names[2 * i + 1];
            inputs[i].start = &starts[i];
            inputs[i].end = &ends[i];
          }
          read_strings(r, monitor_names);
          const bool want_state = r.get<std::uint8_t>() != 0;
          read_strings(r, work_meshes);
          p.run_window(TimeWindow(size, index, 1), inputs, slots.outputs);
          for (const auto& c : slots.combined) out.write(c);
          if (monitor_names.empty())
            out.write(std::uint64_t{0});  // no monitor values
          else
            write_monitors(out, p.monitor_values(monitor_names));
          if (want_state) out.write(p.check_state());
          for (const auto& mesh : work_meshes) {
            const auto w = p.interface_work(mesh);
            out.write(static_cast<std::uint8_t>(w.has_value()));
            if (w) out.write(*w);
          }
          break;
        }
        case Command::mapping: {
          const auto exchange = static_cast<std::size_t>(r.get<std::uint64_t>());
          Mapped m;
          m.mesh = r.get_string();
          m.data = r.get_string();
          const InterfaceMesh sender = read_mesh(r);
          const InterfaceMesh* receiver = p.find_mesh(m.mesh);
          if (!receiver || !mapping)
            throw Error(fmt::format("the controller asked for a mapping to the mesh '{}', which "
                                    "this process cannot set up",
                                    m.mesh));
          Stopwatch clock;
          m.mapping = mapping(exchange, sender, *receiver);
          mapping_seconds_ += clock.seconds();
          mapped.push_back(std::move(m));
          break;
        }
        case Command::save_checkpoint:
          p.save_checkpoint();
          break;
        case Command::restore_checkpoint:
          p.restore_checkpoint();
          break;
        case Command::monitors:
          write_monitors(out, p.monitors());
          break;
        case Command::monitor_values: {
          std::vector<std::string> names_asked;
          read_strings(r, names_asked);
          write_monitors(out, p.monitor_values(names_asked));
          break;
        }
        case Command::check_state:
          out.write(p.check_state());
          break;
        case Command::interface_work: {
          const auto w = p.interface_work(r.view_string());
          out.write(static_cast<std::uint8_t>(w.has_value()));
          if (w) out.write(*w);
          break;
        }
        case Command::write_output: {
          OutputFrame f;
          f.vtk_directory = r.get_string();
          f.prefix = r.get_string();
          f.index = r.get<std::int32_t>();
          f.time = r.get<double>();
          f.vtk.format = static_cast<vtk::Format>(r.get<std::int32_t>());
          f.vtk.zlib_level = r.get<std::int32_t>();
          f.vtk.block_size = r.get<std::uint64_t>();
          f.vtk.precision = static_cast<vtk::Precision>(r.get<std::int32_t>());
          p.write_output(f);  // output time on the controller, not the solver's (as in process)
          break;
        }
        case Command::output_files: {
          std::vector<std::string> a, b;
          for (const auto& [series, file] : p.output_files()) {
            a.push_back(series);
            b.push_back(file);
          }
          write_strings(out, a);
          write_strings(out, b);
          break;
        }
        case Command::write_restart: {
          std::ostringstream bytes;
          BinaryWriter w(bytes);
          p.write_restart(w);
          const BinaryWriter::Recording rec = w.recording(bytes.str());
          out.write(rec.header);
          out.write(static_cast<std::uint64_t>(rec.sections.size()));
          for (const auto& [name, b] : rec.sections) {
            out.write(name);
            out.write(b);
          }
          break;
        }
        case Command::read_restart: {
          const std::string source = r.get_string() + " (participant " + p.name() + ")";
          std::istringstream part(r.get_string());
          BinaryReader in(part, source);
          p.read_restart(in);
          break;
        }
        case Command::substeps:
          out.write(static_cast<std::int32_t>(p.substeps(r.get<double>())));
          break;
        case Command::stable_time_step:
          out.write(p.stable_time_step());
          break;
        case Command::finalize:
          stopped_by = r.get<std::int32_t>();
          p.finalize();
          done = true;
          break;
        default:
          throw Error(fmt::format("the controller sent an unknown request ({})",
                                  static_cast<std::uint32_t>(command)));
      }
    } catch (const std::exception& e) {
      reply.clear();
      MessageWriter failed(reply);
      failed.write(std::uint32_t{1});
      failed.write(std::string(e.what()));
      failed.write(0.0);
      failed.write(std::int32_t{0});
      controller_.send(reply);
      // the controller stops the run and answers with abort (or goes away): wait for it, so
      // this process exits with the run's error, not a timeout
      try {
        controller_.receive(request, "the controller's answer to this error");
      } catch (...) {
      }
      throw;
    }
    const double seconds = p.seconds() - reported_seconds;
    reported_seconds = p.seconds();
    out.write(seconds);
    out.write(static_cast<std::int32_t>(stop_signal_ ? stop_signal_->load() : 0));
    controller_.send(reply);
    if (done) return stopped_by;
  }
}

}  // namespace partita::run
