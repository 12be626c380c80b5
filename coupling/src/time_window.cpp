#include "partita/coupling/time_window.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "partita/interface/error.hpp"

namespace partita::coupling {

TimeWindow::TimeWindow(double size, std::int64_t index, int substeps)
    : size_(size), index_(index), substeps_(substeps) {
  if (!(size > 0.0) || !std::isfinite(size))
    throw Error("time window size must be a positive finite number, found " + std::to_string(size));
  if (substeps < 1)
    throw Error("a window needs at least 1 substep, found " + std::to_string(substeps));
  if (index < 0) throw Error("a window index must be >= 0, found " + std::to_string(index));
}

double TimeWindow::time_at(int k) const {
  if (k >= substeps_) return end();
  // t_{n,k} = t_n + (k / m) Δt
  return start() + size_ * fraction_at(k);
}

void TimeWindow::advance_substep() {
  if (k_ >= substeps_)
    throw Error("window " + std::to_string(index_) + ": all " + std::to_string(substeps_) +
                " substeps are done; start the next window");
  ++k_;
}

TimeWindow TimeWindow::next(int substeps) const {
  return TimeWindow(size_, index_ + 1, substeps > 0 ? substeps : substeps_);
}

namespace {
// ceil(x) where x within TimeWindow::tolerance (relative) of an integer counts as that integer.
double tolerant_ceil(double x) {
  const double r = std::round(x);
  if (std::abs(x - r) <= TimeWindow::tolerance * std::max(1.0, std::abs(x))) return r;
  return std::ceil(x);
}
}  // namespace

std::int64_t TimeWindow::count_to(double end, double size) {
  if (!(size > 0.0))
    throw Error("time window size must be positive, found " + std::to_string(size));
  if (!(end > 0.0) || !std::isfinite(end))
    throw Error("end time must be a positive finite number, found " + std::to_string(end));
  const double n = std::max(1.0, tolerant_ceil(end / size));
  // Window times are n * size with n an integer held exactly in a double: at most 2^53 windows.
  if (!(n <= max_windows))
    throw Error(fmt::format(
        "an end time of {:.6g} s in windows of {:.6g} s needs {:.6g} windows, more than the {:.6g} "
        "(2^53) a run can count exactly; use a larger window or an earlier end",
        end, size, n, max_windows));
  return static_cast<std::int64_t>(n);
}

int TimeWindow::substeps_for(double size, double max_step) {
  if (!(max_step > 0.0))
    throw Error("the solver's stable time step must be positive, found " +
                std::to_string(max_step));
  if (std::isinf(max_step)) return 1;
  const double m = tolerant_ceil(size / max_step);
  if (m > static_cast<double>(std::numeric_limits<int>::max()))
    throw Error("a window of " + std::to_string(size) + " s needs more than 2^31 substeps of " +
                std::to_string(max_step) + " s; use a smaller window");
  return std::max(1, static_cast<int>(m));
}

}  // namespace partita::coupling
