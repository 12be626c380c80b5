#include "partita/fem/velocity_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

VelocityTable::VelocityTable(std::vector<std::pair<double, Vec3>> rows) : rows_(std::move(rows)) {
  if (rows_.empty()) throw Error("velocity table: no rows (give at least one [t, vx, vy, vz])");
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    if (!std::isfinite(rows_[i].first) || !rows_[i].second.allFinite())
      throw Error("velocity table: row " + std::to_string(i + 1) + " has a non-finite value");
    if (i > 0 && !(rows_[i].first > rows_[i - 1].first))
      throw Error("velocity table: the times must increase; row " + std::to_string(i + 1) +
                  " has t = " + std::to_string(rows_[i].first) + " after " +
                  std::to_string(rows_[i - 1].first));
  }
  cumulative_.push_back(Vec3::Zero());
  for (std::size_t i = 1; i < rows_.size(); ++i)
    cumulative_.push_back(cumulative_.back() + 0.5 * (rows_[i].first - rows_[i - 1].first) *
                                                   (rows_[i].second + rows_[i - 1].second));
}

Vec3 VelocityTable::velocity(double t) const {
  if (t <= rows_.front().first) return rows_.front().second;
  if (t >= rows_.back().first) return rows_.back().second;
  const auto it = std::upper_bound(rows_.begin(), rows_.end(), t,
                                   [](double x, const auto& r) { return x < r.first; });
  const auto& [t1, v1] = *it;
  const auto& [t0, v0] = *(it - 1);
  return v0 + (t - t0) / (t1 - t0) * (v1 - v0);
}

Vec3 VelocityTable::integral_from_first(double t) const {
  const double t_first = rows_.front().first;
  if (t <= t_first) return (t - t_first) * rows_.front().second;
  if (t >= rows_.back().first) return cumulative_.back() + (t - rows_.back().first) * rows_.back().second;
  const auto i = static_cast<std::size_t>(
      std::upper_bound(rows_.begin(), rows_.end(), t,
                       [](double x, const auto& r) { return x < r.first; }) -
      rows_.begin() - 1);
  // trapezoid of the linear piece from t_i to t
  return cumulative_[i] + 0.5 * (t - rows_[i].first) * (rows_[i].second + velocity(t));
}

Vec3 VelocityTable::displacement(double t) const {
  return integral_from_first(t) - integral_from_first(0.0);
}

}  // namespace partita::fem
