#include "partita/mpi/mpi_channel.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <thread>

#include <fmt/format.h>

namespace partita::mpi {

namespace {
constexpr int kTag = 7341;
constexpr int kName = 256;
}  // namespace

Membership join(MPI_Comm comm, const std::string& participant, bool several) {
  Membership m;
  MPI_Comm_rank(comm, &m.rank);
  MPI_Comm_size(comm, &m.size);
  // each process's name, and whether it may share its participant with other processes (the
  // name's buffer ends in that flag)
  std::vector<char> mine(kName + 1, '\0'), all(static_cast<std::size_t>(kName + 1) * m.size, '\0');
  std::strncpy(mine.data(), participant.c_str(), kName - 1);
  mine[kName] = several ? 1 : 0;
  MPI_Allgather(mine.data(), kName + 1, MPI_CHAR, all.data(), kName + 1, MPI_CHAR, comm);
  std::vector<char> shares(static_cast<std::size_t>(m.size));
  for (int r = 0; r < m.size; ++r) {
    const char* at = all.data() + static_cast<std::size_t>(r) * (kName + 1);
    m.participants.emplace_back(at);
    shares[static_cast<std::size_t>(r)] = at[kName];
  }
  // the first process of each participant leads it
  for (int r = 0; r < m.size; ++r) {
    int first = 0;
    while (m.participants[first] != m.participants[r]) ++first;
    m.leaders.push_back(first);
  }
  if (std::all_of(m.leaders.begin(), m.leaders.end(), [](int l) { return l == 0; }))
    throw Error(
        m.size < 2
            ? "participant '" + participant +
                  "': this process runs alone; start one process per participant with mpirun, "
                  "e.g. mpirun -n 1 partita run CASE --participant A : -n 1 partita run CASE "
                  "--participant B"
            : fmt::format("all {} processes of the run are participant '{}'; start the other "
                          "participants beside it, e.g. mpirun -n 1 partita run CASE "
                          "--participant A : -n {} partita run CASE --participant {}",
                          m.size, m.participants[0], m.size, m.participants[0]));
  for (int r = 0; r < m.size; ++r)
    if (m.leaders[r] != r && (!shares[r] || !shares[m.leaders[r]]))
      throw Error(fmt::format(
          "participant '{}' is run by the processes of rank {} and {}, and an external program "
          "(partita::mpi::ExternalParticipant) runs one participant in one process; a partita "
          "participant whose solver runs on several ranks may have several: -n K before "
          "its --participant",
          m.participants[r], m.leaders[r], r));
  m.leader = m.leaders[m.rank];
  MPI_Comm_split(comm, m.leader, m.rank, &m.participant_comm);
  MPI_Comm_rank(m.participant_comm, &m.local_rank);
  MPI_Comm_size(m.participant_comm, &m.local_size);
  for (int r = 0; r < m.size; ++r)
    if (m.leaders[r] == m.leader) m.world_ranks.push_back(r);
  return m;
}

MpiChannel::MpiChannel(MPI_Comm comm, int rank, std::string name, double deadline)
    : comm_(comm), rank_(rank), name_(std::move(name)), deadline_(deadline) {}

MpiChannel::~MpiChannel() {
  drain(2.0);
}

void MpiChannel::send(std::string& bytes) {
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Error(fmt::format("a message of {} bytes to {} is above MPI's 2 GiB per message",
                            bytes.size(), name_));
  progress();
  std::unique_ptr<Pending> p;
  if (spare_.empty()) {
    p = std::make_unique<Pending>();
  } else {
    p = std::move(spare_.back());
    spare_.pop_back();
  }
  p->bytes.swap(bytes);  // the caller gets the spare buffer (empty, its capacity kept)
  MPI_Isend(p->bytes.data(), static_cast<int>(p->bytes.size()), MPI_BYTE, rank_, kTag, comm_,
            &p->request);
  pending_.push_back(std::move(p));
}

// Polls `done` (which also moves this side's sends on) until it holds: yielding for the first
// 10 ms (the other side's window is often shorter), then napping up to 1 ms; PeerTimeout after the
// deadline, naming the peer and what was awaited.
template <class Done>
void MpiChannel::wait_for(Done done, std::string_view what, const char* stalled) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  auto nap = std::chrono::microseconds(0);
  while (!done()) {
    const double waited = std::chrono::duration<double>(clock::now() - start).count();
    if (waited > deadline_)
      throw PeerTimeout(fmt::format(
          "{} {} for {:.0f} s while waiting for {} (--peer-timeout {:g}): that process is stuck "
          "or gone",
          name_, stalled, waited, what, deadline_));
    if (waited < 1e-2) {
      std::this_thread::yield();
    } else {
      nap = std::min(std::chrono::microseconds(1000), nap + std::chrono::microseconds(20));
      std::this_thread::sleep_for(nap);
    }
  }
}

void MpiChannel::receive(std::string& bytes, std::string_view what) {
  MPI_Status status;
  wait_for(
      [&] {
        int flag = 0;
        MPI_Iprobe(rank_, kTag, comm_, &flag, &status);
        if (!flag) progress();
        return flag != 0;
      },
      what, "sent nothing");
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  // (a buffer of the same size as the last message is not touched: no allocation, no filling)
  if (bytes.size() != static_cast<std::size_t>(count))
    bytes.resize(static_cast<std::size_t>(count));
  MPI_Recv(bytes.data(), count, MPI_BYTE, rank_, kTag, comm_, MPI_STATUS_IGNORE);
}

void MpiChannel::deliver(std::string_view what) {
  wait_for(
      [&] {
        progress();
        return pending_.empty();
      },
      what, "took nothing");
}

void MpiChannel::drain(double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!pending_.empty() && std::chrono::steady_clock::now() < until) {
    progress();
    if (!pending_.empty()) std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

void MpiChannel::progress() {
  std::size_t done = 0;
  while (done < pending_.size()) {
    int flag = 0;
    MPI_Test(&pending_[done]->request, &flag, MPI_STATUS_IGNORE);
    if (!flag) break;
    pending_[done]->bytes.clear();
    ++done;
  }
  if (done == 0) return;
  for (std::size_t i = 0; i < done; ++i) spare_.push_back(std::move(pending_[i]));
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(done));
}

}  // namespace partita::mpi
