#pragma once
// The processes one participant runs on, through SolverContext::ranks: `mpirun -n N partita run
// CASE` for a case of one participant gives it the N processes of mpirun (its ranks); in a run of
// participants as processes, `mpirun -n 1 partita run CASE --participant plate : -n 3 partita run
// CASE --participant granules` gives granules the three processes of its part of the line (the
// first, its leader, is rank 0 here; world_ranks() maps them to the run's). Without it (null) a
// solver runs in its one process, as always.
//
// Rank 0 leads: the run (the coupling core, the services, every file the run writes; or, as a
// participant among processes, the server of this participant that the controller talks to)
// lives in its process and drives its solver through the Solver contract, as in one process. The
// solver on rank 0 passes what the others must do on to them (its own messages, over the
// communicator); every other rank builds the case alike (the same participant, the same solver set
// up from the same section) and then only follows: the solver hands the app the loop that does so
// (claim()), and the app runs it (follow()) until rank 0's solver says the run has ended.
//
// A solver that does not run on several ranks leaves the handle alone; the app then refuses a run
// on more than one rank, naming the participant and its solver.
//
// The communicator is MPI's (an MPI_Comm, passed as a pointer to it so that interface/ does not
// include mpi.h); only a solver built with MPI reads it.
//
// Stop signals: SIGINT/SIGTERM to a process of the run ends it after the window with a restart
// file. The run reads the signal of rank 0's process; a solver on ranks passes a signal that
// reached another of its ranks alone on to rank 0 (stop_signal() there, raise_stop() on rank 0),
// so that a signal to any one process stops the run.

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace partita {

class ParticipantRanks {
 public:
  /// rank of size processes; communicator: a pointer to their MPI_Comm (alive while the run
  /// is); deadline: seconds any one wait for another rank may take.
  ParticipantRanks(int rank, int size, const void* communicator, double deadline)
      : rank_(rank), size_(size), communicator_(communicator), deadline_(deadline) {}

  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Rank 0: the process the run drives.
  bool leads() const { return rank_ == 0; }
  /// A pointer to the MPI_Comm of the participant's processes.
  const void* communicator() const { return communicator_; }
  double deadline() const { return deadline_; }

  /// The run's rank (MPI_COMM_WORLD) of each of these ranks, where they are part of a larger run
  /// (participants as processes); empty: they are the run's ranks.
  void set_world_ranks(std::vector<int> world) { world_ = std::move(world); }
  const std::vector<int>& world_ranks() const { return world_; }
  /// For messages: how this participant's ranks map to the run's ("" where they are the same),
  /// e.g. " (the participant's ranks 0, 1, 2 are ranks 1, 2, 3 of the run)".
  std::string world_note() const {
    bool same = true;
    for (std::size_t r = 0; r < world_.size(); ++r) same = same && world_[r] == static_cast<int>(r);
    if (same) return {};
    std::string local, world;
    for (std::size_t r = 0; r < world_.size(); ++r) {
      if (r > 0) {
        local.append(", ");
        world.append(", ");
      }
      local.append(std::to_string(r));
      world.append(std::to_string(world_[r]));
    }
    return " (the participant's ranks " + local + " are ranks " + world + " of the run)";
  }

  /// The solver runs on these ranks. On a rank other than 0, `follow` is how it follows rank
  /// 0's solver: it returns the exit status when rank 0's solver ends the run (0 after a run
  /// that finished, non-zero after one that failed on rank 0), and throws on a failure of its
  /// own. On rank 0, `end` tells the others that the run has ended with a status (a failure on
  /// rank 0 outside the solver's calls: the app calls end(), the solver object still alive).
  void claim(std::function<int()> follow, std::function<void(int)> end) {
    claimed_ = true;
    follow_ = std::move(follow);
    end_ = std::move(end);
  }
  bool claimed() const { return claimed_; }
  /// Runs the loop the solver claimed with (ranks other than 0).
  int follow() const { return follow_ ? follow_() : 0; }
  /// (rank 0) Ends the others' loops with `status` (nothing when they have ended already).
  void end(int status) const {
    if (end_) end_(status);
  }

  /// The process's stop flag (the signal number that asked the run to stop, 0: none), which the
  /// app's signal handlers set; null: none.
  void set_stop_flag(std::atomic<int>* flag) { stop_flag_ = flag; }
  /// The signal that reached this process (0: none).
  int stop_signal() const { return stop_flag_ != nullptr ? stop_flag_->load() : 0; }
  /// (rank 0) Another rank's signal: the run stops after the window, as for one to this process
  /// (a signal of this process's own is kept).
  void raise_stop(int signal) const {
    int none = 0;
    if (stop_flag_ != nullptr && signal != 0) stop_flag_->compare_exchange_strong(none, signal);
  }

  /// Set by the solver when a rank failed or stopped answering in the middle of what all ranks
  /// do together: the others cannot finish with it, and the app must end them all (MPI_Abort)
  /// after printing the message.
  void set_broken() { broken_ = true; }
  bool broken() const { return broken_; }

 private:
  int rank_ = 0, size_ = 1;
  const void* communicator_ = nullptr;
  double deadline_ = 600.0;
  std::atomic<int>* stop_flag_ = nullptr;
  bool claimed_ = false;
  bool broken_ = false;
  std::function<int()> follow_;
  std::function<void(int)> end_;
  std::vector<int> world_;
};

}  // namespace partita
