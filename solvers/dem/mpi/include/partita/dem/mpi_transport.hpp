#pragma once
// The subdomains of a split bed (subdomain.hpp) on the ranks of an MPI communicator: rank r steps
// subdomain r (one local subdomain a rank). Library partita::dem_mpi, built where CMake finds
// MPI; the DEM core (partita::dem) stays free of MPI.
//
// exchange(): the sizes (one u64 from every rank to every other, non-blocking point to point)
// and, posted with them, the non-empty buffers, each to its rank, in pieces of at most 1 GiB (MPI
// counts are int); a rank posts its receives once it has the sizes, so an exchange waits for the
// others once, not twice (a rank that shares its core answers a step sooner). The buffer a rank
// sends itself is swapped, not sent. The receive buffers are
// the caller's `in`, resized: no allocation once they have grown. max(): every rank's number to
// every other (8 bytes each), the largest taken in rank order on every rank.
//
// Why point to point and not MPI_Alltoall / MPI_Allreduce: every wait has a deadline, and a rank
// that does not answer must be named. A collective that does not complete says nothing of who
// is missing; a receive from each rank does (and for the few ranks a bed is split over, the
// P - 1 messages of 8 bytes a step cost nothing beside the ghosts' refresh).
//
// Waits: the requests are polled (MPI_Testall), yielding for the first 10 ms, then sleeping in
// growing steps of up to 1 ms, so a waiting rank leaves its core to a working one. Past the
// deadline the call throws PeerTimeout naming the ranks that sent or took nothing and what was
// awaited; the transport is then unusable (requests are left pending) and the caller should end
// the run with MPI_Abort (MPI_Finalize would wait for the silent rank).
//
// Every rank must call exchange() and max() the same number of times in the same order
// (SubdomainStepper does). Messages travel on a duplicate of the communicator (MPI_Comm_idup in
// the constructor, itself awaited with the deadline), so they never meet the caller's own; the
// transport must be destroyed before MPI_Finalize.

#include "partita/dem/error.hpp"
#include "partita/dem/subdomain_transport.hpp"

#include <cstdint>
#include <string>
#include <vector>

#include <mpi.h>

namespace partita::dem {

/// A wait for another rank that ran past its deadline; the caller should MPI_Abort.
struct PeerTimeout : Error {
  using Error::Error;
};

class MpiSubdomainTransport final : public SubdomainTransport {
 public:
  /// Collective over `comm`. deadline: seconds any one wait for the other ranks may take
  /// (> 0). Throws Error on a bad deadline, PeerTimeout when a rank does not join in time.
  MpiSubdomainTransport(MPI_Comm comm, double deadline);
  ~MpiSubdomainTransport() override;
  MpiSubdomainTransport(const MpiSubdomainTransport&) = delete;
  MpiSubdomainTransport& operator=(const MpiSubdomainTransport&) = delete;

  int parts() const override { return size_; }
  /// {this rank}.
  const std::vector<int>& local() const override { return local_; }
  /// out: one outbox (out[0][d]: the bytes for rank d); in[0][s] receives what rank s sent.
  /// Throws Error when out is not one outbox of parts() buffers, PeerTimeout past the deadline.
  void exchange(std::vector<SubdomainMail>& out, std::vector<SubdomainMail>& in) override;
  /// values: this rank's one number; the largest over every rank (the same on all).
  double max(const std::vector<double>& values) override;

  int rank() const { return rank_; }
  double deadline() const { return deadline_; }
  /// The largest piece one MPI message carries [bytes] (1 GiB; a test's knob: smaller pieces
  /// show that a buffer is cut and joined right). Throws Error unless 1 <= bytes <= INT_MAX.
  void set_piece_bytes(std::uint64_t bytes);

 private:
  // what a request waits for, for the message past the deadline
  enum class Kind { size_sent, size_received, data_sent, data_received, value_sent, value_received };
  void post(Kind kind, int peer, MPI_Request request);
  // polls requests_ until all complete, then forgets them; PeerTimeout past the deadline naming
  // what is pending
  void wait_all(const char* what);
  // the same for the first `count` requests, which it keeps (completed: MPI_REQUEST_NULL)
  void wait_first(std::size_t count, const char* what);

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  double deadline_ = 0.0;
  std::uint64_t piece_ = std::uint64_t{1} << 30;
  long calls_ = 0;  // exchange() and max() calls so far (for messages)
  std::vector<int> local_;
  std::vector<std::uint64_t> send_size_, recv_size_;
  std::vector<double> value_;
  std::vector<MPI_Request> requests_;
  std::vector<Kind> kind_;
  std::vector<int> peer_;
};

}  // namespace partita::dem
