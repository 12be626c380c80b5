#include "partita/coupling/coupling_scheme.hpp"

#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/state_archive.hpp"

namespace partita::coupling {

CouplingScheme::CouplingScheme(std::vector<Participant*> participants,
                               std::vector<Exchange*> exchanges)
    : participants_(std::move(participants)), exchanges_(std::move(exchanges)) {}

void CouplingScheme::initialize() {
  for (Participant* p : participants_) {
    outputs_.clear();
    for (Exchange* e : exchanges_)
      if (&e->from() == p) outputs_.push_back(e->window_output());
    p->initial_values(outputs_);
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
  inputs_.clear();  // (capacity kept: no allocation after the first window)
  outputs_.clear();
  for (Exchange* e : exchanges_) {
    if (&e->to() == &p) inputs_.push_back(e->window_input());
    if (&e->from() == &p) outputs_.push_back(e->window_output());
  }
  p.run_window(window, inputs_, outputs_);
}

void CouplingScheme::run_all(const TimeWindow& window) {
  for (Participant* p : participants_)
    if (p->remote()) run_participant(*p, window);
  for (Participant* p : participants_)
    if (!p->remote()) run_participant(*p, window);
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
