// A participant in another process: the controller's proxy (RemoteParticipant), the remote
// side's request loop (ParticipantServer) and the start-up handshake. The message layouts are
// in remote_participant.hpp; each is written and read by one function pair here.
#include "partita/coupling/remote_participant.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/version.hpp"

namespace partita::coupling {

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

// A message under construction: a BinaryWriter over a string stream.
struct Message {
  std::ostringstream stream;
  BinaryWriter out{stream};
  explicit Message(Command c) { out.write(static_cast<std::uint32_t>(c)); }
  Message() = default;
  std::string str() { return std::move(stream).str(); }  // the bytes, moved out (once)
};

// A message received: a BinaryReader over its bytes.
struct Received {
  std::istringstream stream;
  BinaryReader in;
  Received(std::string bytes, const std::string& source)
      : stream(std::move(bytes)), in(stream, source) {}
};

void write_mesh(BinaryWriter& out, const InterfaceMesh& m) {
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

InterfaceMesh read_mesh(BinaryReader& in) {
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

void write_monitors(BinaryWriter& out, const std::vector<MonitorValue>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& m : v) {
    out.write(m.name);
    out.write(m.unit);
    out.write(m.value);
  }
}

std::vector<MonitorValue> read_monitors(BinaryReader& in) {
  std::vector<MonitorValue> v(in.get<std::uint64_t>());
  for (auto& m : v) {
    m.name = in.get_string();
    m.unit = in.get_string();
    m.value = in.get<double>();
  }
  return v;
}

void write_strings(BinaryWriter& out, const std::vector<std::string>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& s : v) out.write(s);
}

// What a participant writes (its outputs' names, shapes and combination), in requests.
void write_outputs(BinaryWriter& out, std::span<const WindowOutput> outputs) {
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
  void read(BinaryReader& in) {
    const auto n = static_cast<std::size_t>(in.get<std::uint64_t>());
    names.resize(3 * n);
    combined.resize(n);
    outputs.assign(n, {});
    for (std::size_t i = 0; i < n; ++i) {
      WindowOutput& o = outputs[i];
      names[3 * i] = in.get_string();
      names[3 * i + 1] = in.get_string();
      o.combines = in.get<std::uint8_t>() ? WriterCombines::average : WriterCombines::last;
      o.points = in.get<std::int64_t>();
      o.components = in.get<std::int32_t>();
      names[3 * i + 2] = in.get_string();
    }
    for (std::size_t i = 0; i < n; ++i) {  // (names is sized: the pointers stay valid)
      outputs[i].mesh = &names[3 * i];
      outputs[i].data = &names[3 * i + 1];
      outputs[i].label = &names[3 * i + 2];
      outputs[i].combined = &combined[i];
    }
  }
};

std::vector<std::string> read_strings(BinaryReader& in) {
  std::vector<std::string> v(in.get<std::uint64_t>());
  for (auto& s : v) s = in.get_string();
  return v;
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
      meshes_(std::move(ready.meshes)),
      supports_restart_(ready.supports_restart),
      maps_inputs_(ready.maps_inputs) {}

std::string RemoteParticipant::read_reply(std::string_view what) const {
  Stopwatch wait;
  std::string bytes = channel_.receive(what);
  wait_seconds_ += wait.seconds();
  ++messages_;
  bytes_received_ += static_cast<double>(bytes.size());
  // [u32 status] [results | error text] [f64 seconds] [i32 signal]: the results are returned
  // in the same string (no copy), the rest read in place
  constexpr std::size_t head = sizeof(std::uint32_t), tail = sizeof(double) + sizeof(std::int32_t);
  if (bytes.size() < head) throw Error(channel_.peer() + " sent a damaged reply");
  std::uint32_t status = 0;
  std::memcpy(&status, bytes.data(), head);
  if (status != 0) {
    Received r(std::move(bytes), channel_.peer());
    r.in.get<std::uint32_t>();
    throw Error(fmt::format("{} failed: {}", channel_.peer(), r.in.get_string()));
  }
  if (bytes.size() < head + tail) throw Error(channel_.peer() + " sent a damaged reply");
  double seconds = 0.0;
  std::int32_t signal = 0;
  std::memcpy(&seconds, bytes.data() + bytes.size() - tail, sizeof(double));
  std::memcpy(&signal, bytes.data() + bytes.size() - sizeof(std::int32_t), sizeof(std::int32_t));
  extra_seconds_ += seconds;
  if (signal != 0) stop_request_ = signal;
  bytes.resize(bytes.size() - tail);
  bytes.erase(0, head);
  return bytes;
}

std::string RemoteParticipant::call(std::string request, std::string_view what) const {
  Stopwatch send;
  bytes_sent_ += static_cast<double>(request.size());
  channel_.send(std::move(request));
  wait_seconds_ += send.seconds();
  std::string reply = read_reply(what);
  const_cast<RemoteParticipant*>(this)->add_seconds(extra_seconds_);
  extra_seconds_ = 0.0;
  return reply;
}

void RemoteParticipant::initial_values(std::span<WindowOutput> outputs) {
  Message m(Command::initial_values);
  write_outputs(m.out, outputs);
  Received r(call(m.str(), "its initial values"), channel_.peer());
  for (WindowOutput& o : outputs) r.in.read(*o.combined);
}

void RemoteParticipant::run_window(const TimeWindow& window, std::span<const WindowInput> inputs,
                                   std::span<WindowOutput> outputs) {
  if (pending_window_) finish_window();
  Message m(Command::run_window);
  m.out.write(window.size());
  m.out.write(static_cast<std::int64_t>(window.index()));
  m.out.write(static_cast<std::uint64_t>(inputs.size()));
  for (const WindowInput& in : inputs) {
    m.out.write(*in.mesh);
    m.out.write(*in.data);
    m.out.write(static_cast<std::uint8_t>(in.sees == ReaderSees::linear));
    m.out.write(static_cast<std::uint8_t>(in.start_is_end));
    // [u8 which travel as the sender's values, the server maps them: 1 end, 2 start]
    const bool start = !in.start_is_end && in.sees == ReaderSees::linear;
    const std::uint8_t unmapped = (in.sent_end ? 1 : 0) | (start && in.sent_start ? 2 : 0);
    m.out.write(unmapped);
    if (start) m.out.write(unmapped & 2 ? *in.sent_start : *in.start);
    m.out.write(unmapped & 1 ? *in.sent_end : *in.end);
  }
  write_outputs(m.out, outputs);
  // What the run asks after a window, answered with the window's reply (one message each way
  // per window): the monitors, the state check and the interface work it asked for before.
  write_strings(m.out, cache_.monitor_names);
  m.out.write(static_cast<std::uint8_t>(cache_.want_state));
  write_strings(m.out, cache_.work_meshes);
  cache_.valid = false;
  Stopwatch send;
  std::string bytes = m.str();
  bytes_sent_ += static_cast<double>(bytes.size());
  channel_.send(std::move(bytes));
  // the peer waits for it: let it start while this process runs its own participants
  channel_.deliver("the window's inputs to be taken");
  wait_seconds_ += send.seconds();
  pending_.assign(outputs.begin(), outputs.end());  // (no allocation after the first window)
  pending_window_ = true;
}

void RemoteParticipant::finish_window() {
  if (!pending_window_) return;
  pending_window_ = false;
  Received r(read_reply("the end of its window"), channel_.peer());
  add_seconds(extra_seconds_);
  extra_seconds_ = 0.0;
  for (WindowOutput& o : pending_) r.in.read(*o.combined);
  cache_.monitors = read_monitors(r.in);
  if (cache_.want_state) cache_.state = r.in.get_string();
  cache_.work.clear();
  for (std::size_t i = 0; i < cache_.work_meshes.size(); ++i) {
    if (r.in.get<std::uint8_t>() != 0)
      cache_.work.emplace_back(r.in.get<double>());
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
      messages_, channel_.peer(), wait_seconds_, seconds(), bytes_sent_ / 1e3,
      bytes_received_ / 1e3);
}

void RemoteParticipant::prepare_mapping(std::size_t exchange, const std::string& mesh,
                                        const std::string& data, const InterfaceMesh& sender) {
  Message m(Command::mapping);
  m.out.write(static_cast<std::uint64_t>(exchange));
  m.out.write(mesh);
  m.out.write(data);
  write_mesh(m.out, sender);
  call(m.str(), "the set-up of the mapping of '" + data + "' to its mesh '" + mesh + "'");
}

int RemoteParticipant::substeps(double window_size) const {
  Message m(Command::substeps);
  m.out.write(window_size);
  Received r(call(m.str(), "its substeps"), channel_.peer());
  return r.in.get<std::int32_t>();
}

double RemoteParticipant::stable_time_step() const {
  Received r(call(Message(Command::stable_time_step).str(), "its stable time step"),
             channel_.peer());
  return r.in.get<double>();
}

void RemoteParticipant::save_checkpoint() {
  call(Message(Command::save_checkpoint).str(), "its checkpoint");
}

void RemoteParticipant::restore_checkpoint() {
  cache_.valid = false;
  call(Message(Command::restore_checkpoint).str(), "the restoring of its checkpoint");
}

std::vector<MonitorValue> RemoteParticipant::monitors() const {
  Received r(call(Message(Command::monitors).str(), "its monitors"), channel_.peer());
  return read_monitors(r.in);
}

std::vector<MonitorValue> RemoteParticipant::monitor_values(
    const std::vector<std::string>& names) const {
  if (cache_.valid && names == cache_.monitor_names) return cache_.monitors;
  cache_.monitor_names = names;  // asked with every window from now on
  Message m(Command::monitor_values);
  write_strings(m.out, names);
  Received r(call(m.str(), "its monitor values"), channel_.peer());
  return read_monitors(r.in);
}

std::string RemoteParticipant::check_state() const {
  if (cache_.valid && cache_.want_state) return cache_.state;
  cache_.want_state = true;
  Received r(call(Message(Command::check_state).str(), "its state check"), channel_.peer());
  return r.in.get_string();
}

std::optional<double> RemoteParticipant::interface_work(std::string_view mesh) const {
  const auto at = std::find(cache_.work_meshes.begin(), cache_.work_meshes.end(), mesh);
  if (cache_.valid && at != cache_.work_meshes.end())
    return cache_.work[static_cast<std::size_t>(at - cache_.work_meshes.begin())];
  if (at == cache_.work_meshes.end()) {
    cache_.work_meshes.emplace_back(mesh);
    cache_.valid = false;  // the cached answers no longer line up with the meshes
  }
  Message m(Command::interface_work);
  m.out.write(std::string(mesh));
  Received r(call(m.str(), "its interface work"), channel_.peer());
  if (r.in.get<std::uint8_t>() == 0) return std::nullopt;
  return r.in.get<double>();
}

void RemoteParticipant::write_output(const OutputFrame& frame) {
  Message m(Command::write_output);
  m.out.write(frame.vtk_directory.string());
  m.out.write(frame.prefix);
  m.out.write(static_cast<std::int32_t>(frame.index));
  m.out.write(frame.time);
  m.out.write(static_cast<std::int32_t>(frame.vtk.format));
  m.out.write(static_cast<std::int32_t>(frame.vtk.zlib_level));
  m.out.write(static_cast<std::uint64_t>(frame.vtk.block_size));
  m.out.write(static_cast<std::int32_t>(frame.vtk.precision));
  call(m.str(), "its output");
}

std::vector<std::pair<std::string, std::string>> RemoteParticipant::output_files() const {
  Received r(call(Message(Command::output_files).str(), "its output files"), channel_.peer());
  const auto a = read_strings(r.in);
  const auto b = read_strings(r.in);
  std::vector<std::pair<std::string, std::string>> files;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) files.emplace_back(a[i], b[i]);
  return files;
}

void RemoteParticipant::write_restart(BinaryWriter& out) const {
  Received r(call(Message(Command::write_restart).str(), "its restart data"), channel_.peer());
  BinaryWriter::Recording rec;
  rec.header = r.in.get_string();
  const auto n = r.in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string name = r.in.get_string();
    rec.sections.emplace_back(std::move(name), r.in.get_string());
  }
  out.replay(rec);
}

void RemoteParticipant::read_restart(BinaryReader& in) {
  // this participant's part: up to the next part of the run's file
  const std::string part = in.raw_until([](const std::string& section) {
    return section.rfind("participant ", 0) == 0 || section == "end";
  });
  cache_.valid = false;
  Message m(Command::read_restart);
  m.out.write(in.source());
  m.out.write(part);
  call(m.str(), "the reading of its restart data");
}

void RemoteParticipant::finalize() {
  Message m(Command::finalize);
  m.out.write(static_cast<std::int32_t>(stop_request_));
  call(m.str(), "its finalize");
}

// ---------------------------------------------------------------------------------------------
// The handshake

Hello receive_hello(Channel& server, const std::string& participant, std::uint64_t case_hash) {
  Received r(server.receive("its start-up message (hello)"), server.peer());
  Hello h;
  h.error = r.in.get_string();
  if (!h.error.empty())
    throw Error(fmt::format("{} failed at set-up: {}", server.peer(), h.error));
  h.version = r.in.get_string();
  h.case_hash = r.in.get<std::uint64_t>();
  h.participant = r.in.get_string();
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
    const std::string why = fmt::format("{} does not match the controller: {}", server.peer(),
                                        mismatch);
    abort_server(server, why);
    throw Error(why);
  }
  const auto n = r.in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) h.meshes.push_back(read_mesh(r.in));
  const auto q = r.in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < q; ++i) {
    std::string name = r.in.get_string();
    h.mesh_requests.emplace_back(std::move(name), r.in.get_string());
  }
  return h;
}

Ready complete_handshake(Channel& server,
                         const std::vector<std::pair<std::string, Mesh>>& meshes) {
  Message m(Command::meshes);
  m.out.write(static_cast<std::uint64_t>(meshes.size()));
  for (const auto& [name, mesh] : meshes) {
    m.out.write(name);
    write_mesh(m.out, InterfaceMesh{mesh, {}, {}});
  }
  server.send(m.str());
  Received r(server.receive("its meshes after the handshake"), server.peer());
  Ready ready;
  ready.error = r.in.get_string();
  if (!ready.error.empty())
    throw Error(fmt::format("{} failed at set-up: {}", server.peer(), ready.error));
  const auto n = r.in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) ready.meshes.push_back(read_mesh(r.in));
  ready.supports_restart = r.in.get<std::uint8_t>() != 0;
  ready.stable_time_step = r.in.get<double>();
  ready.maps_inputs = r.in.get<std::uint8_t>() != 0;
  return ready;
}

void abort_server(Channel& server, const std::string& why) noexcept {
  try {
    Message m(Command::abort);
    m.out.write(why);
    server.send(m.str());
  } catch (...) {
  }
}

// ---------------------------------------------------------------------------------------------
// The remote side

ParticipantServer::ParticipantServer(Channel& controller, const std::atomic<int>* stop_signal)
    : controller_(controller), stop_signal_(stop_signal) {}

void ParticipantServer::fail_setup(const std::string& error) noexcept {
  try {
    Message m;
    m.out.write(error.empty() ? std::string("(no message)") : error);
    controller_.send(m.str());
  } catch (...) {
  }
}

std::vector<std::pair<std::string, Mesh>> ParticipantServer::hello(const Hello& h) {
  {
    Message m;
    m.out.write(std::string());  // no error
    m.out.write(std::string(version()));
    m.out.write(h.case_hash);
    m.out.write(h.participant);
    m.out.write(static_cast<std::uint64_t>(h.meshes.size()));
    for (const auto& mesh : h.meshes) write_mesh(m.out, mesh);
    m.out.write(static_cast<std::uint64_t>(h.mesh_requests.size()));
    for (const auto& [name, source] : h.mesh_requests) {
      m.out.write(name);
      m.out.write(source);
    }
    controller_.send(m.str());
  }
  Received r(controller_.receive("the meshes of the handshake"), controller_.peer());
  const auto c = static_cast<Command>(r.in.get<std::uint32_t>());
  if (c == Command::abort) throw StoppedByController("stopping: " + r.in.get_string());
  if (c != Command::meshes) throw Error("the controller sent a damaged handshake");
  std::vector<std::pair<std::string, Mesh>> got;
  const auto n = r.in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string name = r.in.get_string();
    got.emplace_back(std::move(name), read_mesh(r.in).mesh);
  }
  return got;
}

int ParticipantServer::serve(LocalParticipant& p, const MappingFactory& mapping) {
  {
    Message m;
    m.out.write(std::string());
    m.out.write(static_cast<std::uint64_t>(p.meshes().size()));
    for (const auto& mesh : p.meshes()) write_mesh(m.out, mesh);
    m.out.write(static_cast<std::uint8_t>(p.supports_restart()));
    m.out.write(p.stable_time_step());
    m.out.write(static_cast<std::uint8_t>(static_cast<bool>(mapping)));
    controller_.send(m.str());
  }
  // What run_window() hands the participant, kept between windows (no allocation after the
  // first window but the messages themselves).
  std::vector<std::string> names;  // mesh, data per input
  std::vector<Eigen::MatrixXd> starts, ends;
  std::vector<WindowInput> inputs;
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
    if (at->mapping.scale != 1.0) out *= at->mapping.scale;
    mapping_seconds_ += clock.seconds();
  };
  OutputSlots slots;
  double reported_seconds = 0.0;
  int stopped_by = 0;
  for (;;) {
    Received r(controller_.receive("its next request"), controller_.peer());
    const auto command = static_cast<Command>(r.in.get<std::uint32_t>());
    if (command == Command::abort)
      throw StoppedByController("stopping: " + r.in.get_string());
    Message reply;
    reply.out.write(std::uint32_t{0});
    bool done = false;
    try {
      switch (command) {
        case Command::initial_values: {
          slots.read(r.in);
          p.initial_values(slots.outputs);
          for (const auto& c : slots.combined) reply.out.write(c);
          break;
        }
        case Command::run_window: {
          const double size = r.in.get<double>();
          const auto index = r.in.get<std::int64_t>();
          const auto ni = r.in.get<std::uint64_t>();
          names.resize(2 * ni);
          starts.resize(ni);
          ends.resize(ni);
          inputs.assign(ni, {});
          for (std::uint64_t i = 0; i < ni; ++i) {
            names[2 * i] = r.in.get_string();
            names[2 * i + 1] = r.in.get_string();
            inputs[i].sees = r.in.get<std::uint8_t>() ? ReaderSees::linear : ReaderSees::constant;
            inputs[i].start_is_end = r.in.get<std::uint8_t>() != 0;
            const auto unmapped = r.in.get<std::uint8_t>();
            if (!inputs[i].start_is_end && inputs[i].sees == ReaderSees::linear) {
              if (unmapped & 2) {
                r.in.read(unmapped_values);
                map_into(names[2 * i], names[2 * i + 1], starts[i]);
              } else {
                r.in.read(starts[i]);
              }
            }
            if (unmapped & 1) {
              r.in.read(unmapped_values);
              map_into(names[2 * i], names[2 * i + 1], ends[i]);
            } else {
              r.in.read(ends[i]);
            }
          }
          slots.read(r.in);
          for (std::uint64_t i = 0; i < ni; ++i) {
            inputs[i].mesh = &names[2 * i];
            inputs[i].data = &names[2 * i + 1];
            inputs[i].start = &starts[i];
            inputs[i].end = &ends[i];
          }
          const auto monitor_names = read_strings(r.in);
          const bool want_state = r.in.get<std::uint8_t>() != 0;
          const auto work_meshes = read_strings(r.in);
          p.run_window(TimeWindow(size, index, 1), inputs, slots.outputs);
          for (const auto& c : slots.combined) reply.out.write(c);
          write_monitors(reply.out, monitor_names.empty() ? std::vector<MonitorValue>{}
                                                          : p.monitor_values(monitor_names));
          if (want_state) reply.out.write(p.check_state());
          for (const auto& mesh : work_meshes) {
            const auto w = p.interface_work(mesh);
            reply.out.write(static_cast<std::uint8_t>(w.has_value()));
            if (w) reply.out.write(*w);
          }
          break;
        }
        case Command::mapping: {
          const auto exchange = static_cast<std::size_t>(r.in.get<std::uint64_t>());
          Mapped m;
          m.mesh = r.in.get_string();
          m.data = r.in.get_string();
          const InterfaceMesh sender = read_mesh(r.in);
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
          write_monitors(reply.out, p.monitors());
          break;
        case Command::monitor_values: {
          const auto names_asked = read_strings(r.in);
          write_monitors(reply.out, p.monitor_values(names_asked));
          break;
        }
        case Command::check_state:
          reply.out.write(p.check_state());
          break;
        case Command::interface_work: {
          const auto w = p.interface_work(r.in.get_string());
          reply.out.write(static_cast<std::uint8_t>(w.has_value()));
          if (w) reply.out.write(*w);
          break;
        }
        case Command::write_output: {
          OutputFrame f;
          f.vtk_directory = r.in.get_string();
          f.prefix = r.in.get_string();
          f.index = r.in.get<std::int32_t>();
          f.time = r.in.get<double>();
          f.vtk.format = static_cast<vtk::Format>(r.in.get<std::int32_t>());
          f.vtk.zlib_level = r.in.get<std::int32_t>();
          f.vtk.block_size = r.in.get<std::uint64_t>();
          f.vtk.precision = static_cast<vtk::Precision>(r.in.get<std::int32_t>());
          p.write_output(f);  // output time on the controller, not the solver's (as in process)
          break;
        }
        case Command::output_files: {
          std::vector<std::string> a, b;
          for (const auto& [series, file] : p.output_files()) {
            a.push_back(series);
            b.push_back(file);
          }
          write_strings(reply.out, a);
          write_strings(reply.out, b);
          break;
        }
        case Command::write_restart: {
          std::ostringstream bytes;
          BinaryWriter w(bytes);
          p.write_restart(w);
          const BinaryWriter::Recording rec = w.recording(bytes.str());
          reply.out.write(rec.header);
          reply.out.write(static_cast<std::uint64_t>(rec.sections.size()));
          for (const auto& [name, b] : rec.sections) {
            reply.out.write(name);
            reply.out.write(b);
          }
          break;
        }
        case Command::read_restart: {
          const std::string source = r.in.get_string() + " (participant " + p.name() + ")";
          std::istringstream part(r.in.get_string());
          BinaryReader in(part, source);
          p.read_restart(in);
          break;
        }
        case Command::substeps:
          reply.out.write(static_cast<std::int32_t>(p.substeps(r.in.get<double>())));
          break;
        case Command::stable_time_step:
          reply.out.write(p.stable_time_step());
          break;
        case Command::finalize:
          stopped_by = r.in.get<std::int32_t>();
          p.finalize();
          done = true;
          break;
        default:
          throw Error(fmt::format("the controller sent an unknown request ({})",
                                  static_cast<std::uint32_t>(command)));
      }
    } catch (const std::exception& e) {
      Message failed;
      failed.out.write(std::uint32_t{1});
      failed.out.write(std::string(e.what()));
      failed.out.write(0.0);
      failed.out.write(std::int32_t{0});
      controller_.send(failed.str());
      // the controller stops the run and answers with abort (or goes away): wait for it, so
      // this process exits with the run's error, not a timeout
      try {
        Received last(controller_.receive("the controller's answer to this error"),
                      controller_.peer());
      } catch (...) {
      }
      throw;
    }
    const double seconds = p.seconds() - reported_seconds;
    reported_seconds = p.seconds();
    reply.out.write(seconds);
    reply.out.write(static_cast<std::int32_t>(stop_signal_ ? stop_signal_->load() : 0));
    controller_.send(reply.str());
    if (done) return stopped_by;
  }
}

}  // namespace partita::coupling
