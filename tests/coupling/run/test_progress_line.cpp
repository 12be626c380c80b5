// The progress line: its text and the estimate of the time left.

#include <catch2/catch.hpp>

#include "partita/run/progress_line.hpp"

using partita::run::ProgressLine;

TEST_CASE("progress line: time left from the rate over the windows counted",
          "[coupling][progress]") {
  // 100 windows done of 1000, the last 90 took 9 s: 0.1 s per window, 900 left -> 90 s
  const std::string line = ProgressLine::text(100, 1000, 1e-3, 3, 9.0, 90);
  CHECK(line == "t = 0.001 s  window 100/1000 (10 %)  iterations 3  left ~90 s");
  CHECK(ProgressLine::text(1, 1000, 1e-5, 1, 0.0, 0).find("left ~?") != std::string::npos);
  CHECK(ProgressLine::text(10, 10000, 1.0, 1, 10.0, 10).find("left ~2.8 h") != std::string::npos);
  CHECK(ProgressLine::text(500, 1000, 1.0, 1, 300.0, 500).find("left ~5.0 min") !=
        std::string::npos);
}
