// mpi_pingpong: MPI's own floor under partita's exchange. Two ranks pass a request of
// A bytes and a reply of B bytes back and forth, polling as partita's MpiChannel does (MPI_Isend
// completed with MPI_Test, MPI_Iprobe then MPI_Recv, sched_yield between polls), optionally with
// W microseconds of work on each side between the messages (the data then goes cold in cache, as
// between two coupling windows). Prints the time per round trip and its ratio to the round trip
// of 8-byte messages measured in the same run (the reference).
//
//   mpirun -n 2 build/bench/mpi/mpi_pingpong [--sizes A:B,...] [--work-us W] [--rounds N]
//
// Default sizes: 8:8, 1000:1000 and the steel compaction case's window (request 11.0 kB, reply
// 12.4 kB; bench/README.md).
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

constexpr int kTag = 7;

void receive(std::vector<char>& buffer, int from) {
  MPI_Status status;
  int flag = 0;
  for (;;) {
    MPI_Iprobe(from, kTag, MPI_COMM_WORLD, &flag, &status);
    if (flag) break;
    std::this_thread::yield();
  }
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  if (buffer.size() != static_cast<std::size_t>(count)) buffer.resize(static_cast<std::size_t>(count));
  MPI_Recv(buffer.data(), count, MPI_BYTE, from, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

void send(std::vector<char>& buffer, int to) {
  MPI_Request request;
  MPI_Isend(buffer.data(), static_cast<int>(buffer.size()), MPI_BYTE, to, kTag, MPI_COMM_WORLD,
            &request);
  int flag = 0;
  for (;;) {
    MPI_Test(&request, &flag, MPI_STATUS_IGNORE);
    if (flag) break;
    std::this_thread::yield();
  }
}

void work(double microseconds) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  while (std::chrono::duration<double, std::micro>(clock::now() - start).count() < microseconds) {
  }
}

// microseconds per round trip beyond the work
double round_trips(int rank, int a, int b, double work_us, int rounds) {
  std::vector<char> request(static_cast<std::size_t>(a), 1), reply(static_cast<std::size_t>(b), 2),
      in;
  for (int warm = 0; warm < 2; ++warm) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto start = std::chrono::steady_clock::now();
    const int n = warm == 0 ? rounds / 10 + 1 : rounds;
    for (int i = 0; i < n; ++i) {
      if (rank == 0) {
        work(work_us);
        send(request, 1);
        receive(in, 1);
      } else {
        receive(in, 0);
        work(work_us);
        send(reply, 0);
      }
    }
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    if (warm == 1) return us / n - 2.0 * work_us;
  }
  return 0.0;
}

int usage(int rank, const char* message) {
  if (rank == 0)
    std::fprintf(stderr,
                 "mpi_pingpong: %s\nusage: mpirun -n 2 mpi_pingpong [--sizes A:B,...] "
                 "[--work-us W] [--rounds N]\n",
                 message);
  MPI_Finalize();
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size != 2) return usage(rank, "needs exactly 2 ranks");
  std::vector<std::pair<int, int>> sizes = {{8, 8}, {1000, 1000}, {11000, 12400}};
  double work_us = 0.0;
  int rounds = 5000;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 >= argc) return usage(rank, ("a value is missing after " + arg).c_str());
    const std::string value = argv[++i];
    if (arg == "--sizes") {
      sizes.clear();
      std::istringstream list(value);
      std::string item;
      while (std::getline(list, item, ',')) {
        const auto colon = item.find(':');
        const int a = std::atoi(item.substr(0, colon).c_str());
        const int b = colon == std::string::npos ? a : std::atoi(item.substr(colon + 1).c_str());
        if (a <= 0 || b <= 0) return usage(rank, ("bad size '" + item + "' (A:B bytes, > 0)").c_str());
        sizes.emplace_back(a, b);
      }
    } else if (arg == "--work-us") {
      work_us = std::atof(value.c_str());
      if (work_us < 0.0) return usage(rank, "--work-us must be >= 0");
    } else if (arg == "--rounds") {
      rounds = std::atoi(value.c_str());
      if (rounds < 1) return usage(rank, "--rounds must be >= 1");
    } else {
      return usage(rank, ("unknown option " + arg).c_str());
    }
  }
  const double reference = round_trips(rank, 8, 8, work_us, rounds);
  if (rank == 0)
    std::printf("round trips, %d rounds, %.0f us of work on each side between messages\n", rounds,
                work_us);
  for (const auto& [a, b] : sizes) {
    const double us = round_trips(rank, a, b, work_us, rounds);
    if (rank == 0)
      std::printf("  request %6d B, reply %6d B: %7.1f us per round trip beyond the work "
                  "(%.2fx the 8-byte round trip, %.1f us)\n",
                  a, b, us, us / reference, reference);
  }
  MPI_Finalize();
  return 0;
}
