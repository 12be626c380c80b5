#include "partita/dem/cell_order.hpp"

#include <algorithm>
#include <cmath>

namespace partita::dem {

bool CellOrder::compute(const Particles& p, double skin) {
  const int n = static_cast<int>(p.size());
  if (n < 2) return false;
  Eigen::Vector3d lo = p.position[0], hi = p.position[0];
  double r_max = 0.0;
  for (int i = 0; i < n; ++i) {
    lo = lo.cwiseMin(p.position[i]);
    hi = hi.cwiseMax(p.position[i]);
    r_max = std::max(r_max, p.radius[i]);
  }
  // a position that is not finite cannot be ordered (the neighbour list's build names it)
  if (!lo.allFinite() || !hi.allFinite() || !(hi - lo).allFinite()) return false;
  double h = std::max(2.0 * r_max + std::max(skin, 0.0), 1e-12);
  // counted in doubles: a far particle cannot overflow the product, the cap always holds
  auto dim = [&](int k) { return std::floor((hi[k] - lo[k]) / h) + 1.0; };
  while (dim(0) * dim(1) * dim(2) > 4.0 * n + 64.0) h *= 1.26;
  const long nx = static_cast<long>(dim(0)), ny = static_cast<long>(dim(1)),
             nz = static_cast<long>(dim(2));
  auto cell = [&](double x, double o, long cells) {
    const double c = (x - o) / h;
    if (!(c >= 0.0)) return 0L;  // also NaN
    return c >= static_cast<double>(cells - 1) ? cells - 1 : static_cast<long>(c);
  };
  key_.resize(n);
  start_.reserve(4 * static_cast<std::size_t>(n) + 65);  // the most cells: no regrowth
  start_.assign(nx * ny * nz + 1, 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& x = p.position[i];
    key_[i] = static_cast<int>((cell(x.z(), lo.z(), nz) * ny + cell(x.y(), lo.y(), ny)) * nx +
                               cell(x.x(), lo.x(), nx));
    ++start_[key_[i] + 1];
  }
  for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  order_.resize(n);  // new index -> old index
  for (int i = 0; i < n; ++i) order_[start_[key_[i]]++] = i;
  bool identity = true;
  for (int k = 0; k < n && identity; ++k) identity = order_[k] == k;
  if (identity) return false;
  new_of_old_.resize(n);
  for (int k = 0; k < n; ++k) new_of_old_[order_[k]] = k;
  return true;
}

}  // namespace partita::dem
