#include "partita/coupling/coupling_scheme.hpp"

#include <algorithm>

#include "participant_threads.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/state_archive.hpp"

namespace partita::coupling {

struct CouplingScheme::Threads {
  ParticipantThreads threads;
  std::vector<ParticipantThreads::Job> jobs;  // this process's participants (capacity kept)
  std::vector<double> seconds;                // their Participant::seconds() before the window
};

CouplingScheme::CouplingScheme(std::vector<Participant*> participants,
                               std::vector<Exchange*> exchanges)
    : participants_(std::move(participants)),
      exchanges_(std::move(exchanges)),
      slots_(participants_.size()) {}

CouplingScheme::~CouplingScheme() = default;  // ~Threads joins the workers

void CouplingScheme::stop_threads() {
  if (threads_) threads_->threads.stop();
}

std::vector<int> CouplingScheme::concurrent_omp_threads() const {
  return threads_ ? threads_->threads.omp_threads() : std::vector<int>{};
}

std::size_t CouplingScheme::index_of(const Participant& p) const {
  return static_cast<std::size_t>(
      std::find(participants_.begin(), participants_.end(), &p) - participants_.begin());
}

void CouplingScheme::gather(std::size_t i) {
  Slot& s = slots_[i];
  s.inputs.clear();  // (capacity kept: no allocation after the first window)
  s.outputs.clear();
  for (Exchange* e : exchanges_) {
    if (&e->to() == participants_[i]) s.inputs.push_back(e->window_input());
    if (&e->from() == participants_[i]) s.outputs.push_back(e->window_output());
  }
}

void CouplingScheme::initialize() {
  for (std::size_t i = 0; i < participants_.size(); ++i) {
    gather(i);
    participants_[i]->initial_values(slots_[i].outputs);
  }
  for (Exchange* e : exchanges_) e->initialize();
}

WindowReport CouplingScheme::advance(const TimeWindow& window) {
  WindowReport report = run_window(window);
  for (Exchange* e : exchanges_) e->accept_window();
  return report;
}

// One window of p on its side (subcycling, the inputs' time interpolation and the outputs'
// combination are the participant's): what it reads at the window's ends, what it wrote back.
void CouplingScheme::run_participant(Participant& p, const TimeWindow& window) {
  const std::size_t i = index_of(p);
  gather(i);
  p.run_window(window, slots_[i].inputs, slots_[i].outputs);
}

// The inputs of every participant are fixed before the window starts (nothing is sent until all
// have finished), and each writes only its own outputs' combined values: the participants of
// this process can take the window at the same time, and give the bits they give one by one.
void CouplingScheme::run_all(const TimeWindow& window) {
  std::size_t local = 0;
  for (Participant* p : participants_) {
    if (p->remote())
      run_participant(*p, window);  // sends the window: it works in its process meanwhile
    else
      ++local;
  }
  if (!concurrent_ || local < 2) {
    for (Participant* p : participants_) {
      if (p->remote()) continue;
      try {
        run_participant(*p, window);
      } catch (...) {
        rethrow_from(*p, std::current_exception());
      }
    }
    return;
  }
  if (!threads_) threads_ = std::make_unique<Threads>();
  Threads& t = *threads_;
  t.jobs.clear();
  t.seconds.clear();
  for (std::size_t i = 0; i < participants_.size(); ++i) {
    if (participants_[i]->remote()) continue;
    gather(i);
    t.jobs.push_back({participants_[i], slots_[i].inputs, slots_[i].outputs});
    t.seconds.push_back(participants_[i]->seconds());
  }
  const Stopwatch wall;
  t.threads.run_window(window, t.jobs);
  // what the participants' own times overlapped: their sum over the window's wall time
  double sum = 0.0;
  for (std::size_t j = 0; j < t.jobs.size(); ++j)
    sum += t.jobs[j].participant->seconds() - t.seconds[j];
  overlap_seconds_ += std::max(0.0, sum - wall.seconds());
}

void CouplingScheme::send_outputs(Participant& p) {
  p.finish_window();
  for (Exchange* e : exchanges_) {
    if (&e->from() != &p) continue;
    e->send_combined();  // sent = combined (a swap, no copy)
    e->transmit();
  }
}

void CouplingScheme::serialize(StateArchive& ar) {
  ar.section("scheme " + name());
  for (Exchange* e : exchanges_) e->serialize(ar);
}

}  // namespace partita::coupling
