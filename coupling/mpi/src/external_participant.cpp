// ExternalParticipant (external_participant.hpp): the program's thread and the API's thread hand
// each step over through the Bridge. The API's thread runs the participant server of partita's
// own processes over a LocalParticipant whose Solver is the program: the solver's advance() is
// the program's turn (the program reads, steps, writes and calls advance()), everything else
// (the handshake, the window's messages, the subcycling, the inputs' interpolation, the outputs'
// combination) is the API's turn. Only one of the two threads runs at a time.
#include "partita/mpi/external_participant.hpp"

#include <condition_variable>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "partita/coupling/participant.hpp"
#include "partita/run/remote_participant.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/config.hpp"
#include "partita/mpi/mpi_channel.hpp"

namespace partita::mpi {

class ExternalParticipant::Bridge {
 public:
  // --- shared state (under mutex_) ---
  std::mutex mutex_;
  std::condition_variable cv_;
  enum class Turn { api, program } turn_ = Turn::api;
  bool step_ready_ = false;        // the API waits in the solver's advance(): the program's step
  bool ended_ = false;             // the run ended (finalize received) or stopped
  std::string stopped_;            // why the run stopped elsewhere (empty: it did not)
  std::string program_failed_;     // the program left early (set by the destructor)
  bool write_checkpoint_ = false, read_checkpoint_ = false;
  double step_ = 0.0, time_ = 0.0, checkpoint_time_ = 0.0;
  std::map<std::pair<std::string, std::string>, Eigen::MatrixXd> outputs_;
  coupling::LocalParticipant* local_ = nullptr;  // its window and inputs during the program's turn
  std::map<std::string, MonitorValue> monitors_;
  std::function<std::vector<char>()> restart_writer_;  // the program's state for restart files
  int stop_signal_ = 0;            // the signal that stopped the run early (0: none)
  bool resuming_ = false;          // a restart file gave this participant's part
  std::vector<char> restart_state_;

  // --- set before the thread starts ---
  std::string participant_;
  std::filesystem::path case_file_;
  ExternalOptions options_;
  std::vector<InterfaceMesh> meshes_;
  double stable_ = std::numeric_limits<double>::infinity();
  coupling::Substeps substeps_;
  std::uint64_t case_hash_ = 0;
  bool initialized_mpi_ = false, initialized_ = false, finalized_ = false;
  std::thread thread_;
  std::unique_ptr<MpiChannel> channel_;

  // The API's thread waits for the program's step (called from the solver's advance()).
  void program_turn(double dt) {
    std::unique_lock lock(mutex_);
    step_ = dt;
    step_ready_ = true;
    turn_ = Turn::program;
    cv_.notify_all();
    cv_.wait(lock, [&] { return turn_ == Turn::api; });
    step_ready_ = false;
    if (!program_failed_.empty()) throw Error(program_failed_);
  }
  // The program waits for its next step, or the end of the run.
  void wait_for_step() {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return turn_ == Turn::program || ended_; });
    if (!stopped_.empty()) throw RunStopped(stopped_);
  }
  void end(std::string why) {
    std::lock_guard lock(mutex_);
    ended_ = true;
    stopped_ = std::move(why);
    cv_.notify_all();
  }
  void check_names(std::string_view mesh, std::string_view data, bool reads) const {
    for (const auto& m : meshes_)
      if (m.mesh.name() == mesh)
        for (const auto& d : reads ? m.reads : m.writes)
          if (d.name == data) return;
    throw UsageError(fmt::format("participant '{}' declared no mesh '{}' that {} '{}' (add_mesh)",
                                 participant_, mesh, reads ? "reads" : "writes", data));
  }
};

namespace {

using Bridge = ExternalParticipant::Bridge;

// The program as a partita Solver (called on the API's thread only).
class ProgramSolver final : public Solver {
 public:
  explicit ProgramSolver(Bridge& b) : b_(b) {}
  const std::vector<InterfaceMesh>& meshes() const override { return b_.meshes_; }
  // The program reads the window's inputs itself, at the times it asks for
  // (ExternalParticipant::read(), through the participant's current_inputs()).
  void read(std::string_view, std::string_view, const Eigen::MatrixXd&) override {}
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override {
    std::lock_guard lock(b_.mutex_);
    auto it = b_.outputs_.find({std::string(mesh), std::string(data)});
    if (it == b_.outputs_.end())
      throw Error(fmt::format("the external program of participant '{}' wrote no '{}' on mesh "
                              "'{}' (write() before advance(); the initial value before "
                              "initialize())",
                              b_.participant_, data, mesh));
    values = it->second;
  }
  double stable_time_step() const override { return b_.stable_; }
  void advance(double dt) override { b_.program_turn(dt); }
  double time() const override { return b_.time_; }
  void save_checkpoint() override {
    std::lock_guard lock(b_.mutex_);
    b_.write_checkpoint_ = true;
    b_.checkpoint_time_ = b_.time_;
  }
  void restore_checkpoint() override {
    std::lock_guard lock(b_.mutex_);
    b_.read_checkpoint_ = true;
    b_.write_checkpoint_ = false;
    b_.time_ = b_.checkpoint_time_;
  }
  // Restart files: the time of the program's steps and the bytes of its restart writer (called
  // here, on the API's thread, while the program waits in advance() or initialize()).
  bool supports_restart() const override { return static_cast<bool>(b_.restart_writer_); }
  void write_restart(BinaryWriter& out) const override {
    const std::vector<char> state = b_.restart_writer_();
    std::lock_guard lock(b_.mutex_);
    out.section("external program");
    out.write(b_.time_);
    out.write(state);
  }
  void read_restart(BinaryReader& in) override {
    in.expect_section("external program");
    const auto t = in.get<double>();
    std::vector<char> state;
    in.read(state);
    std::lock_guard lock(b_.mutex_);
    b_.time_ = t;
    b_.restart_state_ = std::move(state);
    b_.resuming_ = true;
  }
  std::vector<MonitorValue> monitors() const override {
    std::lock_guard lock(b_.mutex_);
    std::vector<MonitorValue> v;
    for (const auto& [name, m] : b_.monitors_) v.push_back(m);
    return v;
  }
  void finalize() override {}

 private:
  Bridge& b_;
};

// This program's file name, for the controller's messages ("the program" where unknown).
std::string program_name() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec || exe.filename().empty() ? std::string("the program") : exe.filename().string();
}

// The API's thread: the handshake, then the requests until the run ends.
void serve(Bridge& b) {
  try {
    run::ParticipantServer server(*b.channel_);
    run::Hello h;
    h.case_hash = b.case_hash_;
    h.participant = b.participant_;
    h.program = program_name();
    h.meshes = b.meshes_;
    server.hello(h);  // an external program asks for no meshes
    coupling::LocalParticipant local(b.participant_, std::make_unique<ProgramSolver>(b),
                                     b.substeps_);
    struct Current {  // the program reads the window's inputs through it
      Bridge& b;
      Current(Bridge& bridge, coupling::LocalParticipant& p) : b(bridge) {
        std::lock_guard lock(b.mutex_);
        b.local_ = &p;
      }
      ~Current() {
        std::lock_guard lock(b.mutex_);
        b.local_ = nullptr;
      }
    } current(b, local);
    const int signal = server.serve(local);
    {
      std::lock_guard lock(b.mutex_);
      b.stop_signal_ = signal;
    }
    b.end("");
  } catch (const std::exception& e) {
    b.end(e.what());
  }
}

}  // namespace

ExternalParticipant::ExternalParticipant(std::string participant, std::filesystem::path case_file,
                                         ExternalOptions options)
    : bridge_(std::make_unique<Bridge>()) {
  bridge_->participant_ = std::move(participant);
  bridge_->case_file_ = std::move(case_file);
  bridge_->options_ = std::move(options);
}

ExternalParticipant::~ExternalParticipant() {
  Bridge& b = *bridge_;
  if (b.thread_.joinable()) {
    {
      std::lock_guard lock(b.mutex_);
      if (!b.ended_) {
        b.program_failed_ = "the external program of participant '" + b.participant_ +
                            "' stopped before the end of the run";
        b.turn_ = Bridge::Turn::api;
        b.cv_.notify_all();
      }
    }
    b.thread_.join();
  }
  b.channel_.reset();
  if (b.initialized_mpi_) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  }
}

void ExternalParticipant::add_mesh(InterfaceMesh mesh) {
  if (bridge_->initialized_) throw UsageError("add_mesh() after initialize()");
  bridge_->meshes_.push_back(std::move(mesh));
}

void ExternalParticipant::set_restart_writer(std::function<std::vector<char>()> state) {
  if (bridge_->initialized_) throw UsageError("set_restart_writer() after initialize()");
  if (!state) throw UsageError("set_restart_writer() needs a function that gives the state");
  bridge_->restart_writer_ = std::move(state);
}

bool ExternalParticipant::is_resuming() const {
  if (!bridge_->initialized_) throw UsageError("is_resuming() before initialize()");
  std::lock_guard lock(bridge_->mutex_);
  return bridge_->resuming_;
}

const std::vector<char>& ExternalParticipant::restart_state() const {
  if (!is_resuming())
    throw UsageError("restart_state() of a run that does not resume (ask is_resuming() first)");
  return bridge_->restart_state_;
}

void ExternalParticipant::set_stable_time_step(double dt) {
  if (!(dt > 0.0)) throw UsageError(fmt::format("a stable time step must be > 0, found {}", dt));
  bridge_->stable_ = dt;
}

void ExternalParticipant::initialize() {
  Bridge& b = *bridge_;
  if (b.initialized_) throw UsageError("initialize() twice");
  b.initialized_ = true;
  int ready = 0;
  MPI_Initialized(&ready);
  if (!ready) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    b.initialized_mpi_ = true;
    if (provided < MPI_THREAD_SERIALIZED)
      throw UsageError("this MPI gives no MPI_THREAD_SERIALIZED, which the API needs");
  } else {
    int provided = 0;
    MPI_Query_thread(&provided);
    if (provided < MPI_THREAD_SERIALIZED)
      throw UsageError(
          "MPI was initialised below MPI_THREAD_SERIALIZED; the API sends from a thread of its "
          "own: initialise MPI with MPI_Init_thread(..., MPI_THREAD_SERIALIZED, ...)");
  }
  // Every process of the run joins first (a collective): a failure after it is told to the
  // others, so that none waits for this process.
  const Membership m = join(b.options_.comm, b.participant_);
  if (m.rank != 0)
    b.channel_ = std::make_unique<MpiChannel>(
        b.options_.comm, 0,
        fmt::format("the controller, participant '{}' (rank 0)", m.participants[0]),
        b.options_.peer_timeout);
  try {
    if (m.rank == 0)
      throw UsageError("participant '" + b.participant_ +
                       "' is an external program and the first process of the run; start "
                       "partita first, it runs the coupling core: mpirun -n 1 partita run CASE "
                       "--participant OTHER : -n 1 ./program CASE");
    // The case as every process reads it: its hash, and this participant's substeps.
    const config::Node loaded = config::Node::load_file(b.case_file_, b.options_.overrides);
    b.case_hash_ = run::case_hash(loaded);
    if (!loaded.has("participants") || !loaded["participants"].has(b.participant_))
      throw UsageError("the case " + b.case_file_.string() + " has no participant '" +
                       b.participant_ + "'");
    if (loaded.has("coupling") && loaded["coupling"].has("substeps") &&
        loaded["coupling"]["substeps"].has(b.participant_)) {
      const config::Node s = loaded["coupling"]["substeps"][b.participant_];
      if (s.as_string() == "auto")
        b.substeps_.automatic = true;
      else
        b.substeps_.count = static_cast<int>(s.as_integer());
    }
  } catch (const std::exception& e) {
    const std::string why = "participant '" + b.participant_ + "' (rank " +
                            std::to_string(m.rank) + ", an external program): " + e.what();
    if (m.rank == 0) {
      for (int r = 1; r < m.size; ++r) {
        if (!m.leads_other(r)) continue;  // (the others follow their leader)
        MpiChannel other(b.options_.comm, r, "rank " + std::to_string(r), b.options_.peer_timeout);
        run::abort_server(other, why);
      }
    } else {
      run::ParticipantServer(*b.channel_).fail_setup(e.what());
      try {
        b.channel_->receive("the controller's answer to this failure");
      } catch (...) {
      }
    }
    throw;
  }
  b.thread_ = std::thread([&b] { serve(b); });
  b.wait_for_step();
}

bool ExternalParticipant::is_coupling_ongoing() const {
  std::lock_guard lock(bridge_->mutex_);
  return !bridge_->ended_;
}

int ExternalParticipant::stopped_by_signal() const {
  std::lock_guard lock(bridge_->mutex_);
  return bridge_->stop_signal_;
}

double ExternalParticipant::time_step_size() const {
  std::lock_guard lock(bridge_->mutex_);
  return bridge_->step_;
}

double ExternalParticipant::time() const {
  std::lock_guard lock(bridge_->mutex_);
  return bridge_->time_;
}

bool ExternalParticipant::requires_writing_checkpoint() {
  std::lock_guard lock(bridge_->mutex_);
  return std::exchange(bridge_->write_checkpoint_, false);
}

bool ExternalParticipant::requires_reading_checkpoint() {
  std::lock_guard lock(bridge_->mutex_);
  return std::exchange(bridge_->read_checkpoint_, false);
}

void ExternalParticipant::read(std::string_view mesh, std::string_view data,
                               Eigen::MatrixXd& values) const {
  read(mesh, data, time_step_size(), values);
}

void ExternalParticipant::read(std::string_view mesh, std::string_view data,
                               double relative_read_time, Eigen::MatrixXd& values) const {
  Bridge& b = *bridge_;
  b.check_names(mesh, data, true);
  std::lock_guard lock(b.mutex_);
  if (b.turn_ != Bridge::Turn::program || !b.local_ || !b.local_->current_window())
    throw UsageError("read() outside a step (after initialize(), before advance())");
  if (!(relative_read_time >= 0.0 && relative_read_time <= b.step_))
    throw UsageError(fmt::format(
        "read('{}', '{}', {:.17g}): the relative read time is measured from the start of the "
        "current step (time() = {:.17g} s) and must lie in [0, time_step_size()] = [0, {:.17g}] s",
        mesh, data, relative_read_time, b.time_, b.step_));
  const coupling::WindowInput* in = nullptr;
  for (const coupling::WindowInput& i : b.local_->current_inputs())
    if (*i.mesh == mesh && *i.data == data) in = &i;
  if (!in)
    throw UsageError(fmt::format("no exchange of the case sends '{}' to {}.{}", data,
                                 b.participant_, mesh));
  // The step is substep k + 1 of the window's m (k done): its times [0, dt] are the window's
  // fractions [k/m, (k+1)/m], exactly so at both ends (at dt the fraction a partita
  // participant reads at: the same bits), read as the case's reader_sees gives it.
  const coupling::TimeWindow& w = *b.local_->current_window();
  const double fraction =
      (static_cast<double>(w.substep()) + relative_read_time / b.step_) / w.substeps();
  const Eigen::MatrixXd& seen = coupling::input_at(*in, fraction, values);
  if (&seen != &values) values = seen;
}

void ExternalParticipant::write(std::string_view mesh, std::string_view data,
                                const Eigen::MatrixXd& values) {
  Bridge& b = *bridge_;
  b.check_names(mesh, data, false);
  std::lock_guard lock(b.mutex_);
  if (b.initialized_ && b.turn_ != Bridge::Turn::program)
    throw UsageError("write() outside a step (initial values: before initialize())");
  b.outputs_[{std::string(mesh), std::string(data)}] = values;
}

void ExternalParticipant::set_monitor(const std::string& name, const std::string& unit,
                                      double value) {
  std::lock_guard lock(bridge_->mutex_);
  bridge_->monitors_[name] = MonitorValue{name, unit, value};
}

void ExternalParticipant::advance(double dt) {
  Bridge& b = *bridge_;
  {
    std::lock_guard lock(b.mutex_);
    if (b.turn_ != Bridge::Turn::program)
      throw UsageError("advance() without a step (before initialize() or after the run's end)");
    if (dt != b.step_)
      throw UsageError(fmt::format(
          "advance({:.17g}): the step is {:.17g} s (time_step_size()); the program takes the "
          "steps the case's substeps give",
          dt, b.step_));
    b.time_ += dt;
    b.turn_ = Bridge::Turn::api;
    b.cv_.notify_all();
  }
  b.wait_for_step();
}

void ExternalParticipant::finalize() {
  Bridge& b = *bridge_;
  if (b.finalized_) return;
  b.finalized_ = true;
  if (b.thread_.joinable()) {
    {
      std::lock_guard lock(b.mutex_);
      if (!b.ended_)
        throw UsageError("finalize() while the run goes on (is_coupling_ongoing() is true)");
    }
    b.thread_.join();
  }
  b.channel_.reset();
  if (b.initialized_mpi_) {
    MPI_Finalize();
    b.initialized_mpi_ = false;
  }
}

}  // namespace partita::mpi
