#pragma once
// Participants in other processes. The coupling core runs in one process (the controller: the
// process of the first participant in the scheme order); every other participant runs in a
// process of its own, which builds only its solver and answers the controller's requests
// (ParticipantServer). On the controller such a participant is a RemoteParticipant: the same
// Participant port as a LocalParticipant, whose calls become one request and one reply each.
// The schemes, the mapping, the accelerations, the convergence measures, the audits and the
// common output files stay on the controller, so a run gives the same bits in one process or
// in several: the remote side runs the same LocalParticipant on the same inputs.
//
// The transport is a Channel (a link to one peer: send bytes, receive bytes with a deadline);
// coupling/mpi/ implements it over MPI. Messages are written and read in place in buffers kept
// for the run (MessageWriter, MessageReader: binary_io.hpp, the layout of restart files without
// their sections and checksums):
//
//   request   [u32 command] [arguments]
//   reply     [u32 status: 0 ok, 1 failed] [ok: results | failed: the error text]
//             [f64 solver seconds since the last reply] [i32 signal received (0: none)]
//
// Window exchange: one request and one reply per participant per window (per iteration of an
// implicit scheme): the inputs at the window's ends go out, the outputs combined over the
// substeps come back. A start that equals, to the bit, what the server already holds (the last
// request's end: the next window; its start: the next iteration) travels as a flag only. An input whose exchange maps on the receiver (map_on: receiver, the
// default) travels as the sender's values and the server maps it with its own copy of the
// mapper (set up once by prepare_mapping(): the controller hands over the sender's mesh, the
// server builds the mapper from the case's exchange); the controller maps it too, for its checks,
// audits and restart files, so both hold the same bits. run_window() only sends; finish_window() waits for the reply, so a
// parallel scheme lets every remote participant work while the controller's own one does.
//
// Start-up (handshake), before the first window, each server sends
//   hello: [partita version] [case hash] [participant] [program] [meshes] [mesh requests]
// and the controller answers with the meshes it asked for (another participant's surface),
// after which the server sends its final meshes, stable step, restart support and whether it can
// map what it reads. A mismatch
// (version, case, participant) is an error on both sides naming both.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/interface/config.hpp"

namespace partita::run {

/// A message link to one peer process. A sender keeps one buffer per link and direction: send()
/// takes the message's bytes and hands back a buffer to write the next one into, receive() fills
/// the caller's buffer; once the buffers have grown to the largest message, a window's exchange
/// allocates nothing.
class Channel {
 public:
  virtual ~Channel() = default;
  /// Queue the message in `bytes` for the peer (returns before the peer has received it). Takes
  /// the bytes and leaves in `bytes` an empty buffer for the next message (one whose send has
  /// completed, its capacity kept, where the transport recycles them).
  virtual void send(std::string& bytes) = 0;
  /// The peer's next message, into `bytes` (its storage reused); waits at most deadline()
  /// seconds, then throws partita::Error naming the peer and `what` was awaited.
  virtual void receive(std::string& bytes, std::string_view what) = 0;
  /// The same, into a new string (start-up and failure paths).
  std::string receive(std::string_view what) {
    std::string bytes;
    receive(bytes, what);
    return bytes;
  }
  /// The peer, for messages: the participant it runs and where ("participant 'granules'
  /// (rank 1)"); errors read "<peer> failed: ...".
  virtual std::string peer() const = 0;
  /// The longest wait for one message [s].
  virtual double deadline() const = 0;
  /// Return once the peer has the messages sent so far (at most deadline() seconds). Where a
  /// transport moves a large message only while the sender calls into it (MPI's rendezvous
  /// without a progress thread), a sender that goes off to work would hold the peer up until its
  /// next call: a parallel scheme hands a remote participant its window this way before running
  /// its own. Default: nothing to do (send() delivers).
  virtual void deliver(std::string_view /*what*/) {}
};

/// The hash every process of a distributed run compares at start-up: FNV-1a of the case as loaded
/// (with its --set overrides, before validation) and written back as YAML, so comments, blank
/// lines and quoting do not count.
std::uint64_t case_hash(const config::Node& loaded);

/// Thrown on a server when the controller stopped the run (its reason in the message).
struct StoppedByController : Error {
  using Error::Error;
};

/// What a server says about itself at start-up.
struct Hello {
  std::string version;
  std::uint64_t case_hash = 0;
  std::string participant;
  std::string program;  // its executable's name ("partita", or an external program's), for messages
  std::vector<InterfaceMesh> meshes;
  std::vector<std::pair<std::string, std::string>> mesh_requests;  // (name, participant.mesh)
  std::string error;  // set when its set-up failed (then nothing else is)
};

/// The server's state after the handshake.
struct Ready {
  std::vector<InterfaceMesh> meshes;
  bool supports_restart = false;
  double stable_time_step = 0.0;
  bool maps_inputs = false;  // it can map what it reads (partita's own processes; not an
                             // external program through the participant API)
  std::string error;
};

/// A participant in another process (see the file comment).
class RemoteParticipant final : public coupling::Participant {
 public:
  RemoteParticipant(std::string name, Channel& channel, Ready ready);

  /// Before the first window: the server maps the case's exchange number `exchange` (into its
  /// mesh `mesh`, field `data`) on its side; `sender` is the sender's mesh, handed over.
  void prepare_mapping(std::size_t exchange, const std::string& mesh, const std::string& data,
                       const InterfaceMesh& sender);
  /// Whether its process can map what it reads (else the controller maps it).
  bool maps_inputs() const { return maps_inputs_; }

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void initial_values(std::span<coupling::WindowOutput> outputs) override;
  void run_window(const coupling::TimeWindow& window, std::span<const coupling::WindowInput> inputs,
                  std::span<coupling::WindowOutput> outputs) override;
  void finish_window() override;
  int substeps(double window_size) const override;
  double stable_time_step() const override;
  void save_checkpoint() override;
  void restore_checkpoint() override;
  std::vector<MonitorValue> monitors() const override;
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override;
  std::string check_state() const override;
  std::optional<double> interface_work(std::string_view mesh) const override;
  void write_output(const OutputFrame& frame) override;
  std::vector<std::pair<std::string, std::string>> output_files() const override;
  bool supports_restart() const override { return supports_restart_; }
  void write_restart(BinaryWriter& out) const override;
  void read_restart(BinaryReader& in) override;
  void finalize() override;
  int stop_request() const override { return stop_request_; }
  void note_stop(int signal) override { stop_request_ = signal; }
  bool remote() const override { return true; }
  std::string transport_summary() const override;

 private:
  // The request in request_ sent, its reply read: the results' bytes, in reply_ (throws the
  // server's error, naming the participant).
  std::string_view call(std::string_view what) const;
  std::string_view read_reply(std::string_view what) const;
  Channel& channel_;
  std::string peer_;  // channel_.peer(), for messages
  // The messages' buffers, kept between windows (cleared, not freed).
  mutable std::string request_, reply_;
  std::vector<InterfaceMesh> meshes_;
  bool supports_restart_ = false;
  bool maps_inputs_ = false;
  // A window sent, its reply not yet read: where its outputs go (a copy: the caller's array
  // may be reused for another participant meanwhile, as a parallel scheme does).
  std::vector<coupling::WindowOutput> pending_;
  bool pending_window_ = false;
  // Per input of the last window's request: the values the server holds (as they travelled:
  // the sender's or mapped), so that a start equal to the last end (the next window of an
  // explicit scheme) or to the last start (the next iteration of an implicit one) does not
  // travel again (compared to the bit).
  struct Held {
    const std::string* mesh = nullptr;
    const std::string* data = nullptr;
    bool start_valid = false, start_unmapped = false, end_valid = false, end_unmapped = false;
    Eigen::MatrixXd start, end;
  };
  std::vector<Held> held_;
  mutable int stop_request_ = 0;
  // The answers to the run's questions after a window, sent with the window's reply (valid until
  // the remote state changes: the next window, a restored checkpoint, a restart read).
  struct Cache {
    std::vector<std::string> monitor_names;
    bool want_state = false;
    std::vector<std::string> work_meshes;
    bool valid = false;
    std::vector<MonitorValue> monitors;
    std::string state;
    std::vector<std::optional<double>> work;
  };
  mutable Cache cache_;
  mutable double wait_seconds_ = 0.0;  // in the channel: sending, and waiting for replies
  mutable long messages_ = 0;
  mutable double bytes_sent_ = 0.0, bytes_received_ = 0.0;
  mutable double extra_seconds_ = 0.0;
};

/// A server's mapping of an exchange it maps on its side: the mapper computed from the sender's
/// mesh to its own.
struct ServerMapping {
  std::unique_ptr<coupling::Mapper> mapper;
};
/// Builds a server's mapping from the case: the exchange's number in coupling.exchanges, the
/// sender's mesh (from the controller) and the receiver's (the server's own).
using MappingFactory = std::function<ServerMapping(std::size_t exchange,
                                                   const InterfaceMesh& sender,
                                                   const InterfaceMesh& receiver)>;

/// The remote side: the start-up handshake and the loop that answers the controller's requests
/// with a LocalParticipant, until the run ends (finalize: returns normally) or the controller
/// aborts it (throws partita::Error with the controller's reason).
class ParticipantServer {
 public:
  /// `stop_signal`: the process's signal flag, reported to the controller in every reply.
  ParticipantServer(Channel& controller, const std::atomic<int>* stop_signal = nullptr);
  /// Send the hello (the solver built and asking for meshes); returns the meshes received
  /// for the requests, by request name.
  std::vector<std::pair<std::string, Mesh>> hello(const Hello& h);
  /// Send the set-up failure to the controller (instead of hello). Never throws.
  void fail_setup(const std::string& error) noexcept;
  /// Send the final meshes, then answer requests until the run ends; returns the signal that
  /// stopped the run (0: none; the process exits with 128 + it, as the controller does).
  /// `mapping` builds the mappers of the exchanges this process maps (map_on: receiver).
  int serve(coupling::LocalParticipant& p, const MappingFactory& mapping = {});
  /// Time spent mapping what this process read [s].
  double mapping_seconds() const { return mapping_seconds_; }

 private:
  Channel& controller_;
  const std::atomic<int>* stop_signal_;
  double mapping_seconds_ = 0.0;
};

/// The controller's side of one server's handshake: its hello (checked against this process's
/// version, case hash and the participant expected).
Hello receive_hello(Channel& server, const std::string& participant, std::uint64_t case_hash);
/// Send the meshes a server asked for, and receive its final state.
Ready complete_handshake(Channel& server, const std::vector<std::pair<std::string, Mesh>>& meshes);
/// Tell a server to stop (the run failed: at set-up or later): it throws partita::Error with
/// `why` from hello() or serve(). Never throws.
void abort_server(Channel& server, const std::string& why) noexcept;

}  // namespace partita::run
