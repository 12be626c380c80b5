#pragma once
// The window clock: one time window [t_n, t_n + Δt] of a fixed-size sequence, tiled by m equal
// substeps. Everything is integer counts plus the window size, never an accumulated sum:
//
//   t_n       = n Δt
//   t_{n,k}   = t_n + (k / m) Δt        (k = 0..m; t_{n,m} is exactly t_{n+1} = (n + 1) Δt)
//   "end of window reached"  <=>  k == m  (an integer comparison: no drift however small the steps)
//
// Usage:
//   TimeWindow w(0.01, n, m);
//   while (!w.end_reached()) { solver.advance(w.next_substep_size()); w.advance_substep(); }
//   TimeWindow next = w.next();

#include <cstdint>

namespace partita::coupling {

class TimeWindow {
 public:
  /// Window `index` (0-based) of size `size` [s], tiled by `substeps` >= 1 substeps.
  TimeWindow(double size, std::int64_t index = 0, int substeps = 1);

  std::int64_t index() const { return index_; }
  double size() const { return size_; }
  int substeps() const { return substeps_; }
  /// Substeps completed in this window (0..substeps()).
  int substep() const { return k_; }

  double start() const { return static_cast<double>(index_) * size_; }
  double end() const { return static_cast<double>(index_ + 1) * size_; }
  /// Time after k substeps of this window (k = 0..substeps()); exactly end() for k = substeps().
  double time_at(int k) const;
  /// The current time: time_at(substep()).
  double time() const { return time_at(k_); }
  /// Fraction of the window done after k substeps: k / m (exactly 1 at the end).
  double fraction_at(int k) const {
    return static_cast<double>(k) / static_cast<double>(substeps_);
  }
  /// The length of the next substep, time_at(k + 1) - time_at(k): the substeps tile the window.
  double next_substep_size() const { return time_at(k_ + 1) - time_at(k_); }
  /// The nominal substep Δt / m.
  double substep_size() const { return size_ / static_cast<double>(substeps_); }

  bool end_reached() const { return k_ >= substeps_; }
  /// Count one substep done. Throws partita::Error past the end of the window.
  void advance_substep();
  /// Back to the window start (an implicit scheme repeats the window).
  void restart() { k_ = 0; }
  /// The following window with the same size and `substeps` substeps (0 keeps this count).
  TimeWindow next(int substeps = 0) const;
  /// The same window with another substep count (progress reset).
  TimeWindow with_substeps(int substeps) const { return TimeWindow(size_, index_, substeps); }

  /// The one tolerance of window-time arithmetic, relative: a ratio of times within it of a whole
  /// number counts as that number, and a time within it (times the window) of a target has
  /// reached it. Far above the round-off of a time built from 2^53 windows or fewer (a few ulps
  /// per operation), far below any step a solver takes (a substep is at least 1e-6 of a window
  /// in practice).
  static constexpr double tolerance = 1e-9;

  /// Number of windows of `size` needed to reach `end`: ceil(end / size), where a ratio within
  /// `tolerance` (relative) of a whole number counts as that number (0.3 / 0.1 gives 3, not 4).
  /// Throws partita::Error for a count above max_windows (2^53: window times are exact products).
  static std::int64_t count_to(double end, double size);
  static constexpr double max_windows = 9007199254740992.0;  // 2^53
  /// Substeps for a window of `size` with steps no longer than `max_step`: ceil(size / max_step)
  /// with the same tolerance; 1 when max_step is infinite. Throws if max_step <= 0.
  static int substeps_for(double size, double max_step);
  /// Whether a step of `step` is longer than `max_step` beyond that same tolerance (exactly when
  /// substeps_for(step, max_step) > 1): the one test of a step against a stable step.
  static bool longer_than(double step, double max_step) {
    return substeps_for(step, max_step) > 1;
  }
  /// Whether time t has reached `target` on a clock of windows of `size`: t >= target less
  /// `tolerance` of a window (a time that is a sum or a product of windows rounds either way).
  static bool reached(double t, double target, double size) {
    return t >= target - tolerance * size;
  }

 private:
  double size_;
  std::int64_t index_;
  int substeps_;
  int k_ = 0;
};

}  // namespace partita::coupling
