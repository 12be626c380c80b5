#include "partita/dem/domain_decomposition.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace partita::dem {

DomainDecomposition DomainDecomposition::bisection(const std::vector<Eigen::Vector3d>& positions,
                                                   const Eigen::Vector3d& lo,
                                                   const Eigen::Vector3d& hi, int parts) {
  if (parts < 1)
    throw Error("domain decomposition: the number of subdomains must be >= 1, got " +
                std::to_string(parts));
  for (int d = 0; d < 3; ++d) {
    if (!(lo[d] < hi[d]) || !std::isfinite(lo[d]) || !std::isfinite(hi[d])) {
      std::ostringstream msg;
      msg << "domain decomposition: the box must have lo < hi (finite) in every direction, got lo "
          << lo.transpose() << " and hi " << hi.transpose();
      throw Error(msg.str());
    }
  }
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i].allFinite()) {
      std::ostringstream msg;
      msg << "domain decomposition: position " << i << " is not finite (" << positions[i].transpose()
          << ")";
      throw Error(msg.str());
    }
  }
  DomainDecomposition d;
  d.bounds_ = Box{lo, hi};
  d.boxes_.clear();
  d.nodes_.clear();
  d.boxes_.reserve(static_cast<std::size_t>(parts));
  d.nodes_.reserve(2 * static_cast<std::size_t>(parts));
  std::vector<Eigen::Vector3d> points = positions;
  d.split(points, 0, points.size(), d.bounds_, parts);
  return d;
}

int DomainDecomposition::split(std::vector<Eigen::Vector3d>& points, std::size_t first,
                               std::size_t last, const Box& box, int parts) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{});
  if (parts == 1) {
    nodes_[static_cast<std::size_t>(id)].part = static_cast<int>(boxes_.size());
    boxes_.push_back(box);
    return id;
  }
  int axis = 0;  // the longest extent (the first of equal ones)
  const Eigen::Vector3d extent = box.hi - box.lo;
  for (int a = 1; a < 3; ++a)
    if (extent[a] > extent[axis]) axis = a;
  const int lower_parts = parts / 2;
  const std::size_t n = last - first;
  const std::size_t k = n * static_cast<std::size_t>(lower_parts) / static_cast<std::size_t>(parts);
  const auto first_it = points.begin() + static_cast<std::ptrdiff_t>(first);
  const auto last_it = points.begin() + static_cast<std::ptrdiff_t>(last);
  const auto less = [axis](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return a[axis] < b[axis];
  };
  double at = 0.0;
  if (k == 0 || k == n) {  // no particle to share: in proportion to the subdomains
    at = box.lo[axis] + extent[axis] * lower_parts / parts;
  } else {  // halfway between the k-th and the (k+1)-th coordinate
    const auto kth = first_it + static_cast<std::ptrdiff_t>(k);
    std::nth_element(first_it, kth, last_it, less);
    const double above = (*kth)[axis];
    const double below = (*std::max_element(first_it, kth, less))[axis];
    at = 0.5 * (below + above);
  }
  at = std::clamp(at, box.lo[axis], box.hi[axis]);
  const auto mid_it =
      std::partition(first_it, last_it, [&](const Eigen::Vector3d& x) { return x[axis] < at; });
  const auto mid = static_cast<std::size_t>(mid_it - points.begin());
  Box lower_box = box, upper_box = box;
  lower_box.hi[axis] = at;
  upper_box.lo[axis] = at;
  const int lower = split(points, first, mid, lower_box, lower_parts);
  const int upper = split(points, mid, last, upper_box, parts - lower_parts);
  Node& node = nodes_[static_cast<std::size_t>(id)];  // (after the recursion: nodes_ grew)
  node.axis = axis;
  node.at = at;
  node.lower = lower;
  node.upper = upper;
  return id;
}

int DomainDecomposition::owner(const Eigen::Vector3d& x) const {
  const Node* node = &nodes_[0];
  while (node->axis >= 0)
    node = &nodes_[static_cast<std::size_t>(x[node->axis] < node->at ? node->lower : node->upper)];
  return node->part;
}

double DomainDecomposition::distance(const Eigen::Vector3d& x, int part) const {
  const Box& b = box(part);
  return (x.cwiseMax(b.lo).cwiseMin(b.hi) - x).norm();
}

void DomainDecomposition::near(const Eigen::Vector3d& x, double distance, std::vector<int>& out) const {
  out.clear();
  if (!(distance >= 0.0)) throw Error("domain decomposition: near() takes a distance >= 0");
  near(0, x, distance, owner(x), out);
  std::sort(out.begin(), out.end());
}

void DomainDecomposition::near(int id, const Eigen::Vector3d& x, double d, int owner,
                               std::vector<int>& out) const {
  const Node& node = nodes_[static_cast<std::size_t>(id)];
  if (node.axis < 0) {
    if (node.part != owner && distance(x, node.part) <= d) out.push_back(node.part);
    return;
  }
  if (x[node.axis] - d < node.at) near(node.lower, x, d, owner, out);
  if (x[node.axis] + d >= node.at) near(node.upper, x, d, owner, out);
}

}  // namespace partita::dem
