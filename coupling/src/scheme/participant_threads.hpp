#pragma once
// The participants of a parallel scheme that live in this process, taking a window at the same
// time: participant 0 of the jobs on the calling thread, each other one on a worker thread of its
// own. The workers are persistent (started by the first window, the same thread for the same
// participant every window, joined by stop() or the destructor): a window costs a wake-up and a
// wait, no thread creation and no allocation.
//
//   window n:  caller: jobs[0].run_window()       workers i: jobs[i].run_window()
//              caller waits until every worker has finished the window, then rethrows the first
//              exception by job order (all finish the window first: no participant is left
//              mid-window, and the message does not depend on which thread was faster)
//
// OpenMP: a worker is not an OpenMP thread; a parallel region a participant opens on it gets a
// team of its own. The calling thread's thread count (omp_get_max_threads(), `--threads N`) is
// shared among the participants: participant i gets N / k threads (the first N mod k one more,
// at least 1), set on its worker once and on the calling thread for the window (restored after).
// The solvers give the same bits on any thread count, so the results do not change.
//
// Signals: the workers block the asynchronous ones (SIGINT, SIGTERM, ...): a stop request is
// handled by the calling thread, and the run stops after the window, as without threads.
//
// Waiting: as OpenMP's threads do, a worker waiting for the next window and the caller waiting for
// the workers spin for a while (kSpin, 200 us: longer than the core's work between two windows
// of a light case), then sleep on a condition variable; with OMP_WAIT_POLICY=PASSIVE they sleep
// at once (a loaded machine, the test suite). A sleeping thread's wake-up costs a scheduler
// round trip (10-50 us on an idle machine, milliseconds on a loaded one), twice a window.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "partita/coupling/participant.hpp"
#include "partita/coupling/time_window.hpp"

namespace partita::coupling {

/// Rethrow what participant p threw in its window: a partita::Error names it ("participant
/// 'fluid' failed: <its message>"), any other exception passes unchanged.
[[noreturn]] void rethrow_from(const Participant& p, std::exception_ptr e);

class ParticipantThreads {
 public:
  /// One participant's window: what CouplingScheme::run_participant() would hand over.
  struct Job {
    Participant* participant = nullptr;
    std::span<const WindowInput> inputs;
    std::span<WindowOutput> outputs;
  };

  ParticipantThreads() = default;
  ~ParticipantThreads();
  ParticipantThreads(const ParticipantThreads&) = delete;
  ParticipantThreads& operator=(const ParticipantThreads&) = delete;

  /// Every job takes `window` at the same time (jobs[0] on this thread); returns once all have
  /// finished. The first call starts jobs.size() - 1 workers; later calls must give as many jobs,
  /// the same participant at the same place. Rethrows the first exception by job order
  /// (rethrow_from()).
  void run_window(const TimeWindow& window, std::span<const Job> jobs);

  /// Join the workers (idle between windows); a later run_window() starts new ones.
  void stop();

  /// Workers running (0 before the first window and after stop()).
  std::size_t workers() const { return threads_.size(); }
  /// OpenMP threads each job gets (by job order; empty before the first window, kept by stop()).
  const std::vector<int>& omp_threads() const { return omp_threads_; }

 private:
  void start(std::size_t jobs);
  void work(std::size_t i, std::uint64_t seen);  // worker i runs job i + 1

  std::vector<std::thread> threads_;
  std::vector<int> omp_threads_;
  std::vector<std::exception_ptr> errors_;  // per job, this window's
  // Spin on ready() for up to spin_ (true: it held), else false: sleep on a condition.
  template <class Ready>
  bool spin(Ready ready) const;

  std::chrono::nanoseconds spin_{0};
  std::mutex mutex_;  // for the condition variables (the atomics below change under it too)
  std::condition_variable start_, done_;
  std::atomic<std::uint64_t> generation_{0};  // windows handed out (a worker runs each once)
  std::atomic<std::size_t> pending_{0};       // workers still in this window
  std::atomic<bool> stopping_{false};
  // this window's (set under the mutex before generation_ moves on)
  const TimeWindow* window_ = nullptr;
  std::span<const Job> jobs_;
};

}  // namespace partita::coupling
