// The subdomains of a split bed on MPI ranks (mpi_transport.hpp says how and why).
#include "partita/dem/mpi_transport.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>
#include <thread>

namespace partita::dem {

namespace {

constexpr int kSizeTag = 4801;
constexpr int kDataTag = 4802;
constexpr int kValueTag = 4803;

const char* kind_text(int k) {
  static const char* const text[] = {"the size of a message to",   "the sizes of the messages from",
                                     "a message to",               "a message from",
                                     "its number for the max to",  "the number for the max from"};
  return text[k];
}

}  // namespace

MpiSubdomainTransport::MpiSubdomainTransport(MPI_Comm comm, double deadline) : deadline_(deadline) {
  if (!(deadline > 0.0) || !std::isfinite(deadline))
    throw Error("MpiSubdomainTransport: the deadline must be a finite number of seconds > 0, got " +
                std::to_string(deadline));
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  local_.assign(1, rank_);
  MPI_Request request;
  MPI_Comm_idup(comm, &comm_, &request);
  requests_.push_back(request);
  kind_.push_back(Kind::size_received);
  peer_.push_back(-1);
  wait_all("the duplicate of the communicator (every rank constructs the transport)");
  const auto p = static_cast<std::size_t>(size_);
  send_size_.assign(p, 0);
  recv_size_.assign(p, 0);
  value_.assign(p, 0.0);
  requests_.reserve(4 * p);
  kind_.reserve(4 * p);
  peer_.reserve(4 * p);
}

MpiSubdomainTransport::~MpiSubdomainTransport() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized && comm_ != MPI_COMM_NULL) MPI_Comm_free(&comm_);
}

void MpiSubdomainTransport::set_piece_bytes(std::uint64_t bytes) {
  if (bytes < 1 || bytes > static_cast<std::uint64_t>(INT_MAX))
    throw Error("MpiSubdomainTransport: a piece must be 1 to " + std::to_string(INT_MAX) +
                " bytes (an MPI count is an int), got " + std::to_string(bytes));
  piece_ = bytes;
}

void MpiSubdomainTransport::post(Kind kind, int peer, MPI_Request request) {
  requests_.push_back(request);
  kind_.push_back(kind);
  peer_.push_back(peer);
}

void MpiSubdomainTransport::wait_all(const char* what) {
  wait_first(requests_.size(), what);
  requests_.clear();
  kind_.clear();
  peer_.clear();
}

void MpiSubdomainTransport::wait_first(std::size_t count, const char* what) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto nap = std::chrono::microseconds(0);
  for (;;) {
    int done = 0;
    MPI_Testall(static_cast<int>(count), requests_.data(), &done, MPI_STATUSES_IGNORE);
    if (done) break;
    const double waited = std::chrono::duration<double>(clock::now() - start).count();
    if (waited > deadline_) {
      // which requests are still pending, by rank (MPI_Test completes the others)
      std::ostringstream msg;
      msg << "MpiSubdomainTransport: rank " << rank_ << " of " << size_ << " waited "
          << std::setprecision(3) << waited << " s (deadline " << deadline_ << " s) in call "
          << calls_ << " for " << what << "; still awaited:";
      std::vector<int> silent;
      for (std::size_t k = 0; k < count; ++k) {
        int flag = 0;
        if (requests_[k] != MPI_REQUEST_NULL) MPI_Test(&requests_[k], &flag, MPI_STATUS_IGNORE);
        else flag = 1;
        if (flag) continue;
        if (peer_[k] < 0) {
          msg << " some rank has not joined;";
          continue;
        }
        msg << " " << kind_text(static_cast<int>(kind_[k])) << " rank " << peer_[k] << ";";
        if (std::find(silent.begin(), silent.end(), peer_[k]) == silent.end())
          silent.push_back(peer_[k]);
      }
      std::sort(silent.begin(), silent.end());
      if (!silent.empty()) {
        msg << " rank" << (silent.size() > 1 ? "s" : "");
        for (std::size_t k = 0; k < silent.size(); ++k) msg << (k ? ", " : " ") << silent[k];
        msg << (silent.size() > 1 ? " are" : " is") << " stuck or gone";
      }
      throw PeerTimeout(msg.str());
    }
    if (waited < 1e-2) {
      std::this_thread::yield();
    } else {
      nap = std::min(std::chrono::microseconds(1000), nap + std::chrono::microseconds(20));
      std::this_thread::sleep_for(nap);
    }
  }
}

void MpiSubdomainTransport::exchange(std::vector<SubdomainMail>& out,
                                     std::vector<SubdomainMail>& in) {
  const auto p = static_cast<std::size_t>(size_);
  const auto me = static_cast<std::size_t>(rank_);
  if (out.size() != 1 || out[0].size() != p)
    throw Error("MpiSubdomainTransport::exchange: need one outbox (this rank's subdomain) of " +
                std::to_string(p) + " buffers, one per rank");
  ++calls_;
  in.resize(1);
  in[0].resize(p);
  SubdomainMail& o = out[0];
  SubdomainMail& i = in[0];
  // the sizes, and this rank's buffers sent at once behind them (a receiver matches them once it
  // knows their sizes): one wait for the others instead of two
  for (std::size_t r = 0; r < p; ++r) {
    if (r == me) continue;
    send_size_[r] = o[r].size();
    MPI_Request q;
    MPI_Irecv(&recv_size_[r], 1, MPI_UINT64_T, static_cast<int>(r), kSizeTag, comm_, &q);
    post(Kind::size_received, static_cast<int>(r), q);
    MPI_Isend(&send_size_[r], 1, MPI_UINT64_T, static_cast<int>(r), kSizeTag, comm_, &q);
    post(Kind::size_sent, static_cast<int>(r), q);
  }
  for (std::size_t r = 0; r < p; ++r) {
    if (r == me) continue;
    const std::uint64_t n = o[r].size();
    for (std::uint64_t at = 0; at < n; at += piece_) {
      MPI_Request q;
      MPI_Isend(o[r].data() + at, static_cast<int>(std::min(piece_, n - at)), MPI_BYTE,
                static_cast<int>(r), kDataTag, comm_, &q);
      post(Kind::data_sent, static_cast<int>(r), q);
    }
  }
  wait_first(2 * (p - 1), "the sizes of the messages of an exchange");
  // the receives of the non-empty buffers, in pieces, now that their sizes are in
  for (std::size_t r = 0; r < p; ++r) {
    if (r == me) continue;
    std::vector<std::byte>& b = i[r];
    const std::uint64_t n = recv_size_[r];
    if (n > std::numeric_limits<std::size_t>::max() / 2)
      throw Error("MpiSubdomainTransport::exchange: rank " + std::to_string(r) +
                  " announces a message of " + std::to_string(n) + " bytes");
    b.resize(static_cast<std::size_t>(n));
    for (std::uint64_t at = 0; at < n; at += piece_) {
      MPI_Request q;
      MPI_Irecv(b.data() + at, static_cast<int>(std::min(piece_, n - at)), MPI_BYTE,
                static_cast<int>(r), kDataTag, comm_, &q);
      post(Kind::data_received, static_cast<int>(r), q);
    }
  }
  i[me].swap(o[me]);
  o[me].clear();
  wait_all("the messages of an exchange");
  for (std::size_t r = 0; r < p; ++r)
    if (r != me) o[r].clear();
}

double MpiSubdomainTransport::max(const std::vector<double>& values) {
  if (values.size() != 1)
    throw Error("MpiSubdomainTransport::max: need one number (this rank's subdomain), got " +
                std::to_string(values.size()));
  ++calls_;
  const auto p = static_cast<std::size_t>(size_);
  const auto me = static_cast<std::size_t>(rank_);
  value_[me] = values[0];
  for (std::size_t r = 0; r < p; ++r) {
    if (r == me) continue;
    MPI_Request q;
    MPI_Irecv(&value_[r], 1, MPI_DOUBLE, static_cast<int>(r), kValueTag, comm_, &q);
    post(Kind::value_received, static_cast<int>(r), q);
    MPI_Isend(&value_[me], 1, MPI_DOUBLE, static_cast<int>(r), kValueTag, comm_, &q);
    post(Kind::value_sent, static_cast<int>(r), q);
  }
  wait_all("the numbers of every rank for the max");
  // in rank order, as InProcessTransport takes them
  double m = -std::numeric_limits<double>::infinity();
  for (const double v : value_) m = std::max(m, v);
  return m;
}

}  // namespace partita::dem
