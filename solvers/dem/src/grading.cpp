#include "partita/dem/grading.hpp"

#include <algorithm>
#include <numeric>

namespace partita::dem {

std::vector<Grading::Point> Grading::cumulative(const Particles& p) {
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return p.radius[a] < p.radius[b]; });
  double total = 0.0;
  for (double m : p.mass) total += m;
  std::vector<Point> out;
  double sum = 0.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    sum += p.mass[order[k]];
    const double d = 2.0 * p.radius[order[k]];
    if (k + 1 < order.size() && p.radius[order[k + 1]] == p.radius[order[k]]) continue;
    out.push_back({d, sum / total});
  }
  if (!out.empty()) out.back().passing = 1.0;
  return out;
}

std::vector<double> Grading::passing(const Particles& p, const std::vector<double>& sizes) {
  double total = 0.0;
  for (double m : p.mass) total += m;
  std::vector<double> out(sizes.size(), 0.0);
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    double sum = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (2.0 * p.radius[i] <= sizes[k]) sum += p.mass[i];
    out[k] = total > 0.0 ? sum / total : 0.0;
  }
  return out;
}

}  // namespace partita::dem
