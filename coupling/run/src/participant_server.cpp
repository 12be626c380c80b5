// A participant in another process, the remote side: the request loop (ParticipantServer) that
// answers the controller's proxy (remote_participant.cpp) with its local participant.
#include <algorithm>
#include <cstring>
#include <sstream>  // restart data only (a solver writes it to a BinaryWriter)

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/version.hpp"
#include "partita/run/remote_participant.hpp"
#include "remote_messages.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on
using namespace remote;    // the messages

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
