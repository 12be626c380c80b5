#pragma once
// Stop requests: a signal to this process (SIGINT, SIGTERM) or to another participant's process.
// Every participant is told, and the window carries it (FinishedWindow::signal) to the restart
// files and to the window loop, which ends the run after this window.

#include <atomic>
#include <vector>

#include "partita/coupling/participant.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class StopRequests final : public Service {
 public:
  StopRequests(const std::atomic<int>* signal, std::vector<coupling::Participant*> participants)
      : signal_(signal), participants_(std::move(participants)) {}

  void observe(coupling::FinishedWindow& w) override {
    if (w.initial()) return;
    int signal = signal_ ? signal_->load() : 0;
    for (coupling::Participant* p : participants_)  // a signal to another participant's process
      if (signal == 0) signal = p->stop_request();
    if (signal != 0)
      for (coupling::Participant* p : participants_) p->note_stop(signal);
    w.signal = signal;
  }

 private:
  const std::atomic<int>* signal_;
  std::vector<coupling::Participant*> participants_;
};

}  // namespace partita::run
