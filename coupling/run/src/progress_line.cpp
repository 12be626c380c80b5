#include "partita/run/progress_line.hpp"

#include <unistd.h>
#include <cstdio>

#include <fmt/format.h>

#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

ProgressLine::ProgressLine(std::int64_t windows)
    : windows_(windows), tty_(isatty(fileno(stderr)) != 0) {}

std::string ProgressLine::text(std::int64_t done, std::int64_t windows, double time, int iterations,
                               double elapsed, std::int64_t counted) {
  std::string eta = "?";
  if (counted > 0) {
    // time left = elapsed (windows - done) / counted, elapsed measured over `counted` windows
    const double left =
        elapsed * static_cast<double>(windows - done) / static_cast<double>(counted);
    eta = left < 120    ? fmt::format("{:.0f} s", left)
          : left < 7200 ? fmt::format("{:.1f} min", left / 60)
                        : fmt::format("{:.1f} h", left / 3600);
  }
  return fmt::format(
      "t = {:.6g} s  window {}/{} ({:.0f} %)  iterations {}  left ~{}", time, done, windows,
      windows > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(windows) : 100.0,
      iterations, eta);
}

void ProgressLine::update(std::int64_t done, double time, int iterations) {
  const double now = clock_.seconds();
  const bool last = done >= windows_;
  if (!last && now - last_ < (tty_ ? 0.2 : 10.0)) return;
  last_ = now;
  // The rate is measured from the first window on: it carries one-time costs (factorisations,
  // first neighbour lists) that would make the first estimates far too long.
  if (first_done_ < 0) first_done_ = done, first_seconds_ = now;
  const std::string line =
      text(done, windows_, time, iterations, now - first_seconds_, done - first_done_);
  if (tty_) {
    std::fprintf(stderr, "\r%s\033[K", line.c_str());
    std::fflush(stderr);
    printed_ = true;
  } else {
    log::get("coupling")->info("{}", line);
  }
}

void ProgressLine::finish() {
  if (tty_ && printed_) std::fprintf(stderr, "\n");
  printed_ = false;
}

}  // namespace partita::run
