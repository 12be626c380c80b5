#include "partita/interface/time_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "partita/interface/error.hpp"

namespace partita {

TimeTable::TimeTable(std::vector<std::pair<double, double>> rows) : rows_(std::move(rows)) {
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    if (!std::isfinite(rows_[i].first) || !std::isfinite(rows_[i].second))
      throw Error("time table row " + std::to_string(i) + ": the numbers must be finite");
    if (i > 0 && !(rows_[i].first > rows_[i - 1].first))
      throw Error("time table row " + std::to_string(i) + ": time " +
                  std::to_string(rows_[i].first) + " s does not exceed the previous row's " +
                  std::to_string(rows_[i - 1].first) + " s (times must increase strictly)");
  }
}

const char* TimeTable::doc() {
  return "a table [[t0, f0], [t1, f1], ...] of factors over time: linear between rows, held "
         "before the first and after the last; times strictly increasing";
}

TimeTable TimeTable::from_node(const config::Node& node) {
  if (!node.is_sequence() || node.size() == 0)
    node.fail("expected a table [[t0, f0], [t1, f1], ...] of (time, factor) rows, found " +
              node.describe());
  std::vector<std::pair<double, double>> rows;
  for (const config::Node& row : node.items()) {
    if (!row.is_sequence() || row.size() != 2)
      row.fail("expected a row [time, factor], found " + row.describe());
    const double t = row[0].as_real("s");
    const double f = row[1].as_real();
    if (!rows.empty() && !(t > rows.back().first))
      row[0].fail("time " + row[0].as_string() + " does not exceed the previous row's time (" +
                  std::to_string(rows.back().first) + " s): times must increase strictly");
    rows.emplace_back(t, f);
  }
  return TimeTable(std::move(rows));
}

double TimeTable::operator()(double t) const {
  if (rows_.empty()) return 1.0;
  if (t <= rows_.front().first) return rows_.front().second;
  if (t >= rows_.back().first) return rows_.back().second;
  const auto it = std::upper_bound(rows_.begin(), rows_.end(), t,
                                   [](double x, const auto& r) { return x < r.first; });
  const auto& [t1, f1] = *it;
  const auto& [t0, f0] = *(it - 1);
  // f = f0 + (t - t0) / (t1 - t0) (f1 - f0)
  return f0 + (t - t0) / (t1 - t0) * (f1 - f0);
}

}  // namespace partita
