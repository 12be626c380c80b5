#pragma once
// `partita run CASE --participant NAME` under mpirun: participants as processes, e.g.
//
//   mpirun -n 1 partita run CASE --participant plate : -n 1 partita run CASE --participant granules
//
// Every process reads the same case. The processes find each other by splitting
// MPI_COMM_WORLD by participant (mpi::join()); the process of rank 0 (the first of the mpirun
// line) is the controller: it runs the coupling core (schemes, mapping, accelerations, audits)
// and writes the run's common files (coupling.csv, the monitors' CSV files and plots, restart
// files, the summary); every other participant's first process (its leader) builds only its own
// participant and answers the controller (partita/run/remote_participant.hpp). Each leader writes
// its participant's VTK files into the same output folder (a folder all processes see).
//
// A participant whose solver runs on ranks (a DEM) may have several processes, -n K before its
// --participant (or one with --on-ranks): they are its ranks (ParticipantRanks over the
// participant's communicator); the leader serves the controller (or is the controller, where the
// participant comes first on the line) and its solver drives the others, which build that
// participant alone (check-only) and follow it. A solver that does not take the ranks is refused
// on more than one process, naming the participant.
//
// Every wait for another process has a deadline (--peer-timeout, default 600 s; a participant's
// ranks wait for each other half of it, so that a stalled rank is named by its leader before the
// controller gives up on the leader): a peer that is alive but stuck ends the run with a message
// naming it. A failure anywhere ends every process with the failing participant's message (a rank
// of a participant that fails or stops answering in the middle of the ranks' work together: with
// MPI_Abort, after the message); SIGINT/SIGTERM to any process ends the run after the current
// window everywhere, with a restart file, exit status 128 + signal.

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>

#include "partita/coupling/registries.hpp"
#include "partita/run/case_run.hpp"

namespace partita::app {

struct DistributedOptions {
  std::filesystem::path case_file;
  run::RunOptions run;          ///< as for a run in one process (distributed is set here)
  std::string participant;      ///< the participant this process runs
  double peer_timeout = 600.0;  ///< [s] the longest wait for a message from another process
  /// The participant gets its processes as ranks (ParticipantRanks) even where it has one
  /// (--on-ranks: a DEM steps its split bed, the same bytes on any number of processes); with
  /// more than one it gets them anyway.
  bool on_ranks = false;
  std::atomic<int>* stop_signal = nullptr;
  std::function<void()> install_stop_handlers;
  /// Called on the controller after a run that finished (plots, scripts, the last line).
  std::function<void(const run::CaseRun&)> on_finished;
};

/// Whether this partita can run participants in separate processes (built with MPI).
bool distributed_available();

/// Run this process's part of a distributed run; returns the exit status (0, 1, 128 + signal).
int run_distributed(const coupling::Registries& registries, DistributedOptions options);

/// `mpirun -n N partita run CASE` (no --participant): a case of one participant runs on the N
/// processes (ParticipantRanks, through SolverContext::ranks): rank 0 runs the case (the coupling
/// core, the services, every file), its solver leads the others, which build the case alike and
/// follow it. A case of several participants, or a solver that does not run on ranks, is refused
/// on more than one process; on one (mpirun -n 1) a case whose solver does not take the ranks
/// runs as without mpirun. Returns the exit status (0, 1, 128 + signal); a failure in the middle
/// of what the ranks do together (or a rank that does not answer within peer_timeout) ends them
/// all (MPI_Abort) after the message.
struct RanksOptions {
  std::filesystem::path case_file;
  run::RunOptions run;
  double peer_timeout = 600.0;  ///< [s] the longest wait for another rank
  std::function<void()> install_stop_handlers;
  std::atomic<int>* stop_signal = nullptr;  ///< what the handlers set (the ranks pass it on)
  /// Called on rank 0 after a run that finished (plots, scripts, the last line).
  std::function<void(const run::CaseRun&)> on_finished;
};
int run_on_ranks(const coupling::Registries& registries, RanksOptions options);

/// True when this process was started by mpirun (OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_SIZE
/// set, to any number).
bool started_by_mpirun();

/// True when this process was started by mpirun with others (OMPI_COMM_WORLD_SIZE > 1, or
/// PMI_SIZE > 1): a run without --participant there would run the whole case in every process.
bool started_with_others();

}  // namespace partita::app
