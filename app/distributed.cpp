// Participants as processes over MPI (distributed.hpp): MPI start-up, the processes' names, the
// channels between the controller and the other processes, and the failure paths.
#include "distributed.hpp"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "partita/coupling/remote_participant.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

#ifdef PARTITA_MPI
#include <mpi.h>
#endif

namespace partita::app {

bool started_with_others() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(var); v && std::atoi(v) > 1) return true;
  return false;
}

#ifndef PARTITA_MPI

bool distributed_available() { return false; }

int run_distributed(const coupling::Registries&, DistributedOptions) {
  std::cerr << "partita: error: --participant runs participants as separate processes over MPI, "
               "and this partita was built without MPI (install libopenmpi-dev and openmpi-bin, "
               "e.g. ./build.sh deps, and build again)\n";
  return 1;
}

#else

bool distributed_available() { return true; }

namespace {

constexpr int kTag = 7341;

// A wait for another process that ran past its deadline: the peer may be stuck, so the
// process ends with MPI_Abort (MPI_Finalize would wait for it).
struct PeerTimeout : Error {
  using Error::Error;
};

// One peer over MPI_COMM_WORLD: non-blocking sends (each message's buffer lives until its send
// completes), receives that poll with a deadline (MPI_Iprobe; spinning at first, then sleeping
// in growing steps of up to 1 ms, so a waiting process leaves its core to a working one).
class MpiChannel final : public coupling::Channel {
 public:
  MpiChannel(int rank, std::string name, double deadline)
      : rank_(rank), name_(std::move(name)), deadline_(deadline) {}
  ~MpiChannel() override { drain(2.0); }

  void send(std::string bytes) override {
    if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw Error(fmt::format("a message of {} bytes to {} is above MPI's 2 GiB per message",
                              bytes.size(), name_));
    progress();
    pending_.push_back({std::move(bytes), MPI_REQUEST_NULL});
    Pending& p = pending_.back();
    MPI_Isend(p.bytes.data(), static_cast<int>(p.bytes.size()), MPI_BYTE, rank_, kTag,
              MPI_COMM_WORLD, &p.request);
  }

  std::string receive(std::string_view what) override {
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    auto nap = std::chrono::microseconds(0);
    MPI_Status status;
    for (;;) {
      int flag = 0;
      MPI_Iprobe(rank_, kTag, MPI_COMM_WORLD, &flag, &status);
      if (flag) break;
      progress();
      const double waited = std::chrono::duration<double>(clock::now() - start).count();
      if (waited > deadline_)
        throw PeerTimeout(fmt::format(
            "no message from {} for {:.0f} s while waiting for {} (--peer-timeout {:g}): that "
            "process is stuck or gone",
            name_, waited, what, deadline_));
      if (waited < 1e-3) {
        std::this_thread::yield();
      } else {
        nap = std::min(std::chrono::microseconds(1000), nap + std::chrono::microseconds(20));
        std::this_thread::sleep_for(nap);
      }
    }
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    std::string bytes(static_cast<std::size_t>(count), '\0');
    MPI_Recv(bytes.data(), count, MPI_BYTE, rank_, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return bytes;
  }

  std::string peer() const override { return name_; }
  double deadline() const override { return deadline_; }

  // Complete the sends still under way, waiting at most `seconds`.
  void drain(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!pending_.empty() && std::chrono::steady_clock::now() < until) {
      progress();
      if (!pending_.empty()) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }

 private:
  struct Pending {
    std::string bytes;
    MPI_Request request;
  };
  void progress() {
    while (!pending_.empty()) {
      int done = 0;
      MPI_Test(&pending_.front().request, &done, MPI_STATUS_IGNORE);
      if (!done) return;
      pending_.pop_front();
    }
  }
  int rank_;
  std::string name_;
  double deadline_;
  std::deque<Pending> pending_;  // std::deque: a push never moves the buffers under way
};

}  // namespace

int run_distributed(const coupling::Registries& registries, DistributedOptions o) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  auto logger = log::get("app");
  auto fail = [&](const std::string& what, bool stuck) {
    std::cerr << "partita: error: " << what << "\n";
    if (stuck) MPI_Abort(MPI_COMM_WORLD, 1);  // a stuck peer would hold MPI_Finalize forever
    MPI_Finalize();
    return 1;
  };

  // Who runs what: every process's participant name (the participants' communicators split
  // COMM_WORLD by it; one process per participant: the solvers are not MPI-parallel, they use
  // threads).
  constexpr int kName = 256;
  std::vector<char> mine(kName, '\0'), all(static_cast<std::size_t>(kName) * size, '\0');
  std::strncpy(mine.data(), o.participant.c_str(), kName - 1);
  MPI_Allgather(mine.data(), kName, MPI_CHAR, all.data(), kName, MPI_CHAR, MPI_COMM_WORLD);
  std::vector<std::string> names(size);
  for (int r = 0; r < size; ++r) names[r] = std::string(all.data() + static_cast<std::size_t>(r) * kName);
  if (size < 2)
    return fail("--participant " + o.participant +
                    ": this process runs alone; start one process per participant with mpirun, "
                    "e.g. mpirun -n 1 partita run CASE --participant A : -n 1 partita run CASE "
                    "--participant B (or leave out --participant to run every participant here)",
                false);
  for (int r = 0; r < size; ++r)
    for (int q = r + 1; q < size; ++q)
      if (names[r] == names[q])
        return fail(fmt::format("participant '{}' is run by the processes of rank {} and {}: each "
                                "participant runs in one process (it uses threads: --threads)",
                                names[r], r, q),
                    false);
  int color = 0;
  while (names[color] != o.participant) ++color;
  MPI_Comm participant_comm = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, color, rank, &participant_comm);

  std::vector<std::unique_ptr<MpiChannel>> channels;
  coupling::RunOptions& ro = o.run;
  ro.distributed.participant = o.participant;
  if (rank == 0) {
    for (int r = 1; r < size; ++r) {
      channels.push_back(std::make_unique<MpiChannel>(
          r, fmt::format("participant '{}' (rank {})", names[r], r), o.peer_timeout));
      ro.distributed.servers.emplace_back(names[r], channels.back().get());
    }
  } else {
    channels.push_back(std::make_unique<MpiChannel>(
        0, fmt::format("the controller, participant '{}' (rank 0)", names[0]), o.peer_timeout));
    ro.distributed.controller = channels.back().get();
  }
  const std::string who = fmt::format("participant '{}' (rank {})", o.participant, rank);
  int status = 0;
  bool built = false;
  try {
    coupling::CaseRun c(o.case_file, registries, ro);
    built = true;
    if (o.install_stop_handlers) o.install_stop_handlers();
    c.run();
    if (const int signal = c.summary().stopped_by_signal; signal != 0) {
      std::cout << "partita run: " << who << " stopped by signal " << signal;
      if (rank == 0) std::cout << " after window " << c.summary().windows;
      std::cout << "\n";
      status = 128 + signal;
    } else if (rank == 0) {
      if (o.on_finished) o.on_finished(c);
    } else {
      std::cout << "partita run: " << who << " finished\n";
    }
  } catch (const std::exception& e) {
    const bool stuck = dynamic_cast<const PeerTimeout*>(&e) != nullptr;
    const std::string what = dynamic_cast<const Error*>(&e)
                                 ? std::string(e.what())
                                 : "internal error: " + std::string(e.what());
    if (rank == 0) {
      for (auto& ch : channels) coupling::abort_server(*ch, who + " stopped the run: " + what);
    } else if (!built && !stuck) {
      // the controller waits for this process's hello or final meshes: tell it, and wait for its
      // answer so that it can name this failure before every process ends
      coupling::ParticipantServer(*channels.front()).fail_setup(what);
      try {
        channels.front()->receive("the controller's answer to this failure");
      } catch (...) {
      }
    }
    for (auto& ch : channels) ch->drain(2.0);
    channels.clear();
    MPI_Comm_free(&participant_comm);
    return fail(who + ": " + what, stuck);
  }
  channels.clear();
  MPI_Comm_free(&participant_comm);
  MPI_Finalize();
  return status;
}

#endif

}  // namespace partita::app
