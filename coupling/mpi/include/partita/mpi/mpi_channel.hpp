#pragma once
// The run library's Channel (partita/run/remote_participant.hpp) over MPI, and how the processes
// of a distributed run find each other.
//
// Every process of the run (partita run --participant, or an external program through
// ExternalParticipant) calls join() first, with the same communicator (MPI_COMM_WORLD by
// default): it gathers every process's participant name and splits the communicator by
// participant. A participant may run on several processes (mpirun ... : -n 3 partita run CASE
// --participant granules) where its solver runs on ranks (an external program has one
// process): the first of them, its leader, is the one the others talk to; the rest follow the
// leader over the participant's communicator (partita/interface/participant_ranks.hpp). The
// process of rank 0 is the controller (and the leader of its own participant); it has a channel
// to each other participant's leader, every other leader one to rank 0.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <mpi.h>

#include "partita/interface/error.hpp"
#include "partita/run/remote_participant.hpp"

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
  std::vector<int> leaders;  ///< by rank: the rank of the first process of its participant
  int leader = 0;            ///< this participant's leader (the lowest rank that runs it)
  /// This participant's processes, ordered by rank (the leader has rank 0 in it).
  MPI_Comm participant_comm = MPI_COMM_NULL;
  int local_rank = 0, local_size = 1;  ///< in participant_comm
  std::vector<int> world_ranks;        ///< by local rank: the rank in `comm`
  /// Whether rank r leads a participant other than the controller's (a peer of the controller).
  bool leads_other(int r) const { return leaders[r] == r && leaders[r] != leaders[0]; }
};

/// Gather the participants' names over `comm` (collective: every process of the run calls it);
/// throws partita::Error (on every process alike) where the run has one participant only, or a
/// participant has several processes and one of them does not allow it (`several`: false for an
/// external program).
Membership join(MPI_Comm comm, const std::string& participant, bool several = false);

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
