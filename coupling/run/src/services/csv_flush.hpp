#pragma once
// The run's CSV files are rewritten whole at each flush (always complete on disk): every service's
// flush every 2 s, or less often once a flush takes longer than 2 % of the interval (very long
// runs).

#include <algorithm>
#include <vector>

#include "partita/coupling/stopwatch.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class CsvFlush final : public Service {
 public:
  explicit CsvFlush(std::vector<Service*> services) : services_(std::move(services)) {}
  void observe(coupling::FinishedWindow& w) override {
    if (w.initial() || since_flush_.seconds() <= interval_) return;
    coupling::Stopwatch flush_clock;
    for (Service* s : services_) s->flush();
    interval_ = std::max(2.0, 50.0 * flush_clock.seconds());
    since_flush_.restart();
  }

 private:
  std::vector<Service*> services_;
  coupling::Stopwatch since_flush_;
  double interval_ = 2.0;  // [s]
};

}  // namespace partita::run
