#pragma once
// The progress of a long run on one line of stderr: simulated time, window, iterations and an
// estimate of the time left. Updated in place (carriage return) on a terminal, at most 5 times a
// second; otherwise logged at info every 10 s.

#include <cstdint>
#include <string>

#include "partita/coupling/stopwatch.hpp"

namespace partita::run {

class ProgressLine {
 public:
  explicit ProgressLine(std::int64_t windows);
  /// After window `done` (1-based count) at time t with that window's iterations.
  void update(std::int64_t done, double time, int iterations);
  /// End the line (newline on a terminal).
  void finish();
  /// The text of the line for these values: the time left is estimated from `elapsed` seconds
  /// spent on the last `counted` windows ("?" when counted is 0).
  static std::string text(std::int64_t done, std::int64_t windows, double time, int iterations,
                          double elapsed, std::int64_t counted);

 private:
  std::int64_t windows_;
  bool tty_;
  coupling::Stopwatch clock_;
  double last_ = -1e300;
  std::int64_t first_done_ = -1;  // the window of the first update and its time
  double first_seconds_ = 0.0;
  bool printed_ = false;
};

}  // namespace partita::run
