#pragma once
// What the subdomains of a split bed (subdomain.hpp) need from whatever connects them: byte
// buffers to and from every other subdomain, and the largest of one number over all of them.
//
// A process steps one or more subdomains (its local ones, local()); the stepper calls every
// collective the same number of times in the same order on every process:
//   exchange(out, in)  out[k][d]: the bytes local subdomain k sends to subdomain d (an empty buffer:
//                      nothing); on return in[k][s] holds what subdomain s sent to local
//                      subdomain k (empty: nothing). The buffers of `out` may be left with any
//                      content (the senders clear them before they write).
//   max(values)        values[k]: local subdomain k's number; returns the largest over all
//                      subdomains (the rebuild decision: any subdomain's wish makes all rebuild).
// InProcessTransport: every subdomain in this process (tests, and a bed split in one process).
// MpiSubdomainTransport (one subdomain a rank; library partita::dem_mpi in solvers/dem/mpi, so that
// partita::dem stays free of MPI): the sizes first, then the non-empty buffers to their ranks, and
// the max from every rank's number, every wait with a deadline (partita/dem/mpi_transport.hpp).

#include <cstddef>
#include <vector>

namespace partita::dem {

/// One byte buffer per subdomain (by rank).
using SubdomainMail = std::vector<std::vector<std::byte>>;

class SubdomainTransport {
 public:
  virtual ~SubdomainTransport() = default;
  /// The number of subdomains in all.
  virtual int parts() const = 0;
  /// The ranks of the subdomains this process steps, ascending.
  virtual const std::vector<int>& local() const = 0;
  virtual void exchange(std::vector<SubdomainMail>& out, std::vector<SubdomainMail>& in) = 0;
  virtual double max(const std::vector<double>& values) = 0;
};

/// Every subdomain local: in[d][s] takes out[s][d]'s bytes (swapped, not copied: no allocation
/// once the buffers have grown).
class InProcessTransport final : public SubdomainTransport {
 public:
  explicit InProcessTransport(int parts);
  int parts() const override { return static_cast<int>(local_.size()); }
  const std::vector<int>& local() const override { return local_; }
  void exchange(std::vector<SubdomainMail>& out, std::vector<SubdomainMail>& in) override;
  double max(const std::vector<double>& values) override;

 private:
  std::vector<int> local_;
};

}  // namespace partita::dem
