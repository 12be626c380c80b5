#pragma once
// A factor over time from a table of (time, factor) rows, as a case writes it:
//
//   table: [[0, 0], [0.01, 1], [0.05, 1], [0.06, 0]]     # ramp up, hold, release
//
// f(t) is linear between rows and held at the first / last factor before / after them. Times
// must increase strictly; every number must be finite. Reals may carry units ("10 ms").

#include <utility>
#include <vector>

#include "partita/interface/config.hpp"

namespace partita {

class TimeTable {
 public:
  TimeTable() = default;
  /// From rows (t_i, f_i); throws partita::Error unless the times increase strictly.
  explicit TimeTable(std::vector<std::pair<double, double>> rows);
  /// From a YAML sequence of [time, factor] pairs; errors name the row and what is allowed.
  static TimeTable from_node(const config::Node& node);
  /// The YAML text that config::Spec shows in docs.
  static const char* doc();

  /// f(t): linear between rows, constant outside them; 1 for an empty table.
  double operator()(double t) const;
  const std::vector<std::pair<double, double>>& rows() const { return rows_; }
  bool empty() const { return rows_.empty(); }

 private:
  std::vector<std::pair<double, double>> rows_;
};

}  // namespace partita
