#include "participant_threads.hpp"

#include <algorithm>
#include <cstdlib>
#include <csignal>
#include <stdexcept>

#include <pthread.h>
#include <strings.h>

#include "partita/interface/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::coupling {

namespace {

int omp_max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void omp_set_threads([[maybe_unused]] int n) {
#ifdef _OPENMP
  omp_set_num_threads(n);  // this thread's count (an ICV of the calling thread only)
#endif
}

// This thread's OpenMP thread count for a scope, restored at its end.
class OmpThreadsScope {
 public:
  explicit OmpThreadsScope(int n) : before_(omp_max_threads()) {
    if (n != before_) omp_set_threads(n);
  }
  ~OmpThreadsScope() {
    if (omp_max_threads() != before_) omp_set_threads(before_);
  }
  OmpThreadsScope(const OmpThreadsScope&) = delete;
  OmpThreadsScope& operator=(const OmpThreadsScope&) = delete;

 private:
  int before_;
};

// The asynchronous signals blocked for a scope on the calling thread (a thread started inside
// the scope inherits the mask): the workers never run a signal handler.
class BlockSignals {
 public:
  BlockSignals() {
    sigset_t all;
    sigfillset(&all);
    for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP}) sigdelset(&all, s);
    pthread_sigmask(SIG_BLOCK, &all, &before_);
  }
  ~BlockSignals() { pthread_sigmask(SIG_SETMASK, &before_, nullptr); }
  BlockSignals(const BlockSignals&) = delete;
  BlockSignals& operator=(const BlockSignals&) = delete;

 private:
  sigset_t before_;
};

constexpr std::chrono::microseconds kSpin{200};

// Spin, or sleep at once: OMP_WAIT_POLICY=PASSIVE (case-insensitive) asks for the latter.
bool passive_wait() {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  return policy != nullptr && strcasecmp(policy, "passive") == 0;
}

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

}  // namespace

template <class Ready>
bool ParticipantThreads::spin(Ready ready) const {
  if (spin_.count() == 0) return ready();
  const auto until = std::chrono::steady_clock::now() + spin_;
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (ready()) return true;
      cpu_relax();
    }
    if (std::chrono::steady_clock::now() >= until) return ready();
  }
}

void rethrow_from(const Participant& p, std::exception_ptr e) {
  try {
    std::rethrow_exception(e);
  } catch (const Error& error) {
    throw Error("participant '" + p.name() + "' failed: " + error.what());
  }
}

ParticipantThreads::~ParticipantThreads() { stop(); }

void ParticipantThreads::start(std::size_t jobs) {
  // N threads of the caller among k participants: N / k each, the first N mod k one more.
  const int n = omp_max_threads(), k = static_cast<int>(jobs);
  omp_threads_.assign(jobs, 1);
  for (int i = 0; i < k; ++i) omp_threads_[i] = std::max(1, n / k + (i < n % k ? 1 : 0));
  errors_.assign(jobs, nullptr);
  spin_ = passive_wait() ? std::chrono::nanoseconds(0) : std::chrono::nanoseconds(kSpin);
  const BlockSignals blocked;
  threads_.reserve(jobs - 1);
  const std::uint64_t seen = generation_.load();  // the windows before these are not theirs
  for (std::size_t i = 0; i + 1 < jobs; ++i)
    threads_.emplace_back([this, i, seen] { work(i, seen); });
}

void ParticipantThreads::work(std::size_t i, std::uint64_t seen) {
  omp_set_threads(omp_threads_[i + 1]);
  const auto ready = [&] {
    return stopping_.load(std::memory_order_acquire) ||
           generation_.load(std::memory_order_acquire) != seen;
  };
  for (;;) {
    if (!spin(ready)) {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, ready);
    }
    if (stopping_.load(std::memory_order_acquire)) return;
    seen = generation_.load(std::memory_order_acquire);  // window_, jobs_ are this window's
    const Job& job = jobs_[i + 1];
    try {
      job.participant->run_window(*window_, job.inputs, job.outputs);
    } catch (...) {
      errors_[i + 1] = std::current_exception();
    }
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      const std::lock_guard<std::mutex> lock(mutex_);  // (the caller may be about to sleep)
      done_.notify_one();
    }
  }
}

void ParticipantThreads::run_window(const TimeWindow& window, std::span<const Job> jobs) {
  if (jobs.empty()) return;
  if (threads_.empty()) {
    if (jobs.size() == 1) {  // nobody to wait for
      try {
        jobs[0].participant->run_window(window, jobs[0].inputs, jobs[0].outputs);
      } catch (...) {
        rethrow_from(*jobs[0].participant, std::current_exception());
      }
      return;
    }
    start(jobs.size());
  }
  if (jobs.size() != threads_.size() + 1)
    throw std::logic_error("ParticipantThreads::run_window: a different number of participants");
  window_ = &window;  // (published by the release below; no worker reads them until then)
  jobs_ = jobs;
  {
    const std::lock_guard<std::mutex> lock(mutex_);  // (a worker may be about to sleep)
    pending_.store(threads_.size(), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
  }
  start_.notify_all();
  {
    const OmpThreadsScope threads(omp_threads_[0]);
    try {
      jobs[0].participant->run_window(window, jobs[0].inputs, jobs[0].outputs);
    } catch (...) {
      errors_[0] = std::current_exception();
    }
  }
  const auto finished = [&] { return pending_.load(std::memory_order_acquire) == 0; };
  if (!spin(finished)) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, finished);
  }
  std::exception_ptr first;
  std::ptrdiff_t failed = -1;
  for (std::size_t i = 0; i < errors_.size(); ++i) {
    if (errors_[i] && !first) {
      first = errors_[i];
      failed = static_cast<std::ptrdiff_t>(i);
    }
    errors_[i] = nullptr;
  }
  if (first) rethrow_from(*jobs[static_cast<std::size_t>(failed)].participant, first);
}

void ParticipantThreads::stop() {
  if (threads_.empty()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_.store(true, std::memory_order_release);
  }
  start_.notify_all();
  for (std::thread& t : threads_) t.join();
  threads_.clear();
  errors_.clear();
  stopping_.store(false);
}

}  // namespace partita::coupling
