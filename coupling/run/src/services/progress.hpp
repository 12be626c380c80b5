#pragma once
// The progress line (progress_line.hpp) as a service: updated after each window, ended with the
// run.

#include <cstdint>

#include "partita/run/progress_line.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class Progress final : public Service {
 public:
  explicit Progress(std::int64_t windows) : line_(windows) {}
  void observe(coupling::FinishedWindow& w) override {
    if (w.initial()) return;
    line_.update(w.window, w.time, w.report->iterations);
    if (w.signal != 0) line_.finish();
  }
  void finish(bool /*failed*/) override { line_.finish(); }

 private:
  ProgressLine line_;
};

}  // namespace partita::run
