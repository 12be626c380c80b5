#include <catch2/catch.hpp>

#include "partita/coupling/time_window.hpp"
#include "partita/interface/error.hpp"

using partita::coupling::TimeWindow;

TEST_CASE("TimeWindow: a million tiny substeps reach the window end exactly, without drift",
          "[coupling][time]") {
  const int m = 1000000;
  TimeWindow w(1.0e-3, 41, m);
  double summed = w.start();  // what an accumulating clock would do
  int steps = 0;
  while (!w.end_reached()) {
    summed += w.substep_size();
    w.advance_substep();
    ++steps;
  }
  CHECK(steps == m);  // "end of window reached" after exactly m substeps
  CHECK(w.time() == w.end());
  CHECK(w.end() == w.next().start());
  // A clock that accumulated dt / m would have drifted (why this one counts instead).
  CHECK(std::abs(summed - w.end()) > 0.0);
  // every substep time is within rounding of the exact t_n + k/m dt
  CHECK(w.time_at(m / 2) == Approx(41.5e-3).epsilon(1e-15));
}

TEST_CASE("TimeWindow: substeps tile the window exactly and counts are robust",
          "[coupling][time]") {
  TimeWindow w(0.1, 7, 3);
  double total = 0.0;
  while (!w.end_reached()) {
    total += w.next_substep_size();
    w.advance_substep();
  }
  CHECK(total == Approx(0.1).epsilon(1e-15));
  CHECK_THROWS_AS(w.advance_substep(), partita::Error);
  CHECK(TimeWindow::count_to(1.0, 0.01) ==
        100);  // 1.0 / 0.01 = 100.00000000000001 in floating point
  CHECK(TimeWindow::count_to(0.3, 0.1) == 3);
  CHECK(TimeWindow::count_to(0.35, 0.1) == 4);
  CHECK(TimeWindow::substeps_for(1e-5, 1.9e-6) == 6);
  CHECK(TimeWindow::substeps_for(1e-5, 2e-6) == 5);
  CHECK(TimeWindow::substeps_for(1e-5, INFINITY) == 1);
  CHECK_THROWS_AS(TimeWindow(0.0), partita::Error);
  CHECK_THROWS_AS(TimeWindow(0.1, 0, 0), partita::Error);
}

TEST_CASE("TimeWindow: one tolerance for steps against a stable step and for reached times",
          "[coupling][time]") {
  // a step is longer than the stable one exactly when it would need two substeps
  CHECK_FALSE(TimeWindow::longer_than(1e-5, 1e-5));
  CHECK_FALSE(TimeWindow::longer_than(1e-5 * (1.0 + 1e-12), 1e-5));  // round-off of a division
  CHECK(TimeWindow::longer_than(1e-5 * (1.0 + 1e-6), 1e-5));
  CHECK_FALSE(TimeWindow::longer_than(1.0, INFINITY));
  for (const double step : {1e-7, 3.3e-6, 1e-5, 0.7})
    for (const double stable : {2e-7, 1e-6, 9.9e-6, 0.1})
      CHECK(TimeWindow::longer_than(step, stable) == (TimeWindow::substeps_for(step, stable) > 1));
  // 3 windows of 0.1 s end at 0.30000000000000004 > 0.3: reached, and 0.1 is not 0.2
  CHECK(TimeWindow::reached(3 * 0.1, 0.3, 0.1));
  CHECK(TimeWindow::reached(0.3, 3 * 0.1, 0.1));
  CHECK_FALSE(TimeWindow::reached(0.1, 0.2, 0.1));
}
