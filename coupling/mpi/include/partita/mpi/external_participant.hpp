#pragma once
// The API for a program that keeps its own time loop (its own FE code, a legacy solver) and
// joins a partita run as one participant over MPI, shaped like preCICE's Participant:
//
//   partita::mpi::ExternalParticipant p("solid", "tube.yaml");      // the case's participant
//   p.add_mesh({partita::Mesh("nodes", points), {{"pressure", 1, "Pa"}}, {{"cross_section_area", 1, "m^2"}}});
//   p.set_restart_writer([&] { return my_state_as_bytes(); });       // optional: restart files
//   p.initialize();                                                    // the handshake
//   if (p.is_resuming()) restore_my_state(p.restart_state());         // partita run --resume
//   while (p.is_coupling_ongoing()) {
//     if (p.requires_writing_checkpoint()) { save my state }
//     const double dt = p.time_step_size();
//     p.read("nodes", "pressure", pressure);                         // at the end of the step
//     p.read("nodes", "pressure", 0.5 * dt, mid);                    // or at any time of it
//     my_solver.step(dt, pressure); p.write("nodes", "cross_section_area", area);
//     p.advance(dt);
//     if (p.requires_reading_checkpoint()) { restore my state }      // the window is repeated
//   }
//   p.finalize();
//
// and is started beside partita (which must be the first process: it runs the coupling core):
//
//   mpirun -n 1 partita run tube.yaml --participant fluid : -n 1 ./my_solver tube.yaml
//
// In the case the participant is `solid: {solver: external}` (any further keys are the program's
// own); its substeps come from `coupling.substeps` (a number, or auto from
// set_stable_time_step()). The program takes the steps the API gives (time_step_size(): the
// window's substeps, as a partita participant takes them) and reads each input at the time of the
// step it asks for (relative to the step's start, as preCICE v3's relativeReadTime; the step's
// end by default) with the case's reader_sees (linear: interpolated between the window's ends by
// the same function, coupling::input_at(), as partita's own participants; constant: the window
// end's value); what it writes is combined over the window's steps with the case's
// writer_combines. Inside, the API runs the same participant code as partita's own processes (a
// LocalParticipant over a Solver that hands each step to the program), so a program that
// computes what an in-tree solver computes gives the in-process run's results bit for bit,
// iteration counts of implicit schemes included.
//
// Restart: with a restart writer the participant's part of each restart file is the time of its
// steps and the writer's bytes; a run resumed on partita's side (partita run ... --resume DIR,
// the program started as for a new run) gives them back through is_resuming() and
// restart_state(). A SIGINT/SIGTERM to a process of the run ends the loop after the window
// (stopped_by_signal()). `partita check CASE` checks the case but the program's own meshes,
// fields and quantities, which the handshake checks when it joins.
//
// The messages to the controller go from a thread of the API's while the program waits in
// initialize(), advance() or finalize() (MPI_THREAD_SERIALIZED is enough; the API initialises
// MPI with it unless the program did, and finalises what it initialised).

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <mpi.h>

#include <Eigen/Core>

#include "partita/interface/error.hpp"
#include "partita/interface/solver.hpp"

namespace partita::mpi {

/// A call out of order or with a name the participant did not declare (the program's bug).
struct UsageError : Error {
  using Error::Error;
};
/// The run ended elsewhere: another participant failed, a signal, or the controller refused this
/// process at start-up (the message says which).
struct RunStopped : Error {
  using Error::Error;
};

struct ExternalOptions {
  std::vector<std::string> overrides;  ///< "KEY.PATH=VALUE", as partita run --set (same on every process)
  MPI_Comm comm = MPI_COMM_WORLD;      ///< the communicator of the run's processes
  double peer_timeout = 600.0;         ///< [s] the longest wait for the controller
};

class ExternalParticipant {
 public:
  ExternalParticipant(std::string participant, std::filesystem::path case_file,
                      ExternalOptions options = {});
  /// Ends the run with an error if it is still going (the program stopped early).
  ~ExternalParticipant();
  ExternalParticipant(const ExternalParticipant&) = delete;
  ExternalParticipant& operator=(const ExternalParticipant&) = delete;

  // Before initialize():
  /// A coupling mesh with the fields the program reads and writes on it.
  void add_mesh(InterfaceMesh mesh);
  /// The largest step the program can take (substeps: auto); default: no limit.
  void set_stable_time_step(double dt);
  /// Restart files: `state` gives the program's state as bytes. Called each time the run writes
  /// a restart file (output.restart, the run's end, SIGINT/SIGTERM to partita), between windows,
  /// on a thread of the API's while the program waits in advance() (never while the program's
  /// own code runs). Without it the run writes no restart files (and refuses output.restart).
  void set_restart_writer(std::function<std::vector<char>()> state);

  // After initialize():
  /// Whether the run resumes from a restart file (partita run ... --resume DIR): then time() is
  /// the restart point's and restart_state() the bytes `state` gave there; restore them before
  /// the first step.
  bool is_resuming() const;
  const std::vector<char>& restart_state() const;

  /// Join the run (the handshake); throws RunStopped where the controller refuses it.
  void initialize();
  /// False once the run has ended (after the last window, or early: stopped_by_signal()).
  bool is_coupling_ongoing() const;
  /// Once the run has ended: the signal (SIGINT, SIGTERM to a process of the run) that stopped it
  /// after a window, with a restart file where the program has a restart writer; 0 when it ran to
  /// its end. (partita's processes then exit with 128 + it.)
  int stopped_by_signal() const;
  /// The step to take now [s] (advance() must be given it).
  double time_step_size() const;
  /// The time at the start of the step [s].
  double time() const;
  /// True at the start of a window an implicit scheme may repeat: save the state.
  bool requires_writing_checkpoint();
  /// True after advance() when the window is repeated: restore the state saved.
  bool requires_reading_checkpoint();
  /// An input at the end of the current step (N x components): read(mesh, data,
  /// time_step_size(), values).
  void read(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) const;
  /// An input at `relative_read_time` [s] after the start of the current step (as preCICE v3's
  /// relativeReadTime: 0 the step's start, time_step_size() its end), as the case's reader_sees
  /// gives it: `linear` interpolates between the window's ends, `constant` gives the window
  /// end's value. Throws UsageError for a time outside [0, time_step_size()].
  void read(std::string_view mesh, std::string_view data, double relative_read_time,
            Eigen::MatrixXd& values) const;
  /// An output at the end of the current step (N x components).
  void write(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values);
  /// A scalar for the case's monitors (participant.<name>), reported after each window.
  void set_monitor(const std::string& name, const std::string& unit, double value);
  /// The step is done.
  void advance(double dt);
  /// After the last window (is_coupling_ongoing() false), or to leave.
  void finalize();

  class Bridge;  // the hand-over between the program's thread and the API's

 private:
  std::unique_ptr<Bridge> bridge_;
};

}  // namespace partita::mpi
