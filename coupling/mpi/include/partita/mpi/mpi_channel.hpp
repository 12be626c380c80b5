#pragma once
// The run library's Channel (partita/run/remote_participant.hpp) over MPI, and how the processes
// of a distributed run find each other.
//
// Every process of the run (partita run --participant, or an external program through
// ExternalParticipant) calls join() first, with the same communicator (MPI_COMM_WORLD by
// default): it gathers every process's participant name, checks that each participant has one
// process, and splits the communicator by participant. The process of rank 0 is the controller;
// it has a channel to each other process, every other process one to rank 0.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <mpi.h>

#include "partita/run/remote_participant.hpp"
#include "partita/interface/error.hpp"

namespace partita::mpi {

/// A wait for another process that ran past its deadline: the peer may be stuck, so the caller
/// should end with MPI_Abort (MPI_Finalize would wait for it).
struct PeerTimeout : Error {
  using Error::Error;
};

/// Who runs what.
struct Membership {
  int rank = 0;
  int size = 1;
  std::vector<std::string> participants;  ///< by rank
  MPI_Comm participant_comm = MPI_COMM_NULL;  ///< this participant's processes (one today)
};

/// Gather the participants' names over `comm` (collective: every process of the run calls it);
/// throws partita::Error (on every process alike) where a participant has several processes or
/// the run has one process only.
Membership join(MPI_Comm comm, const std::string& participant);

/// One peer: non-blocking sends (each message's buffer lives until its send completes, then is
/// handed back to a later send() for the next message: no allocation once the buffers have
/// grown), receives that poll with a deadline (MPI_Iprobe; yielding for the first 10 ms, then
/// sleeping in growing steps of up to 1 ms, so a waiting process leaves its core to a working
/// one) and receive into the caller's buffer (MPI_Get_count, then MPI_Recv into it).
class MpiChannel final : public run::Channel {
 public:
  MpiChannel(MPI_Comm comm, int rank, std::string name, double deadline);
  ~MpiChannel() override;
  void send(std::string& bytes) override;
  void receive(std::string& bytes, std::string_view what) override;
  using run::Channel::receive;
  std::string peer() const override { return name_; }
  double deadline() const override { return deadline_; }
  /// Completes the sends under way (OpenMPI moves a message above the eager limit, 4 KB over
  /// shared memory, only while the sender calls MPI); throws PeerTimeout after deadline().
  void deliver(std::string_view what) override;
  /// Complete the sends still under way, waiting at most `seconds`.
  void drain(double seconds);

 private:
  struct Pending {
    std::string bytes;
    MPI_Request request = MPI_REQUEST_NULL;
  };
  void progress();
  template <class Done>
  void wait_for(Done done, std::string_view what, const char* stalled);
  MPI_Comm comm_;
  int rank_;
  std::string name_;
  double deadline_;
  // Sends under way, oldest first, and finished ones whose buffers wait for reuse. Each on the
  // heap: its bytes never move while MPI reads them (a short string's bytes live in the object).
  std::vector<std::unique_ptr<Pending>> pending_, spare_;
};

}  // namespace partita::mpi
