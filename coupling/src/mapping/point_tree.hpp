#pragma once
// A k-d tree (nanoflann) over the rows of an N x 3 point matrix. Private to the mappers:
// nanoflann is a PRIVATE dependency of partita::coupling, so no public header includes this.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace partita::coupling {

class PointTree {
 public:
  using Points = Eigen::MatrixX3d;

  /// The tree keeps a reference to `points`: they must outlive it and not change.
  explicit PointTree(const Points& points)
      : adaptor_{points}, index_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    index_.buildIndex();
  }
  PointTree(const PointTree&) = delete;
  PointTree& operator=(const PointTree&) = delete;

  Eigen::Index size() const { return adaptor_.points.rows(); }

  /// Index of the nearest point and its squared distance.
  std::pair<Eigen::Index, double> nearest(const Eigen::Vector3d& q) const {
    std::uint32_t i = 0;
    double d2 = 0.0;
    index_.knnSearch(q.data(), 1, &i, &d2);
    return {static_cast<Eigen::Index>(i), d2};
  }

  /// The k nearest points (fewer if the tree holds fewer), sorted by distance.
  /// `index` and `dist2` are resized to the number found.
  void nearest(const Eigen::Vector3d& q, std::size_t k, std::vector<std::uint32_t>& index,
               std::vector<double>& dist2) const {
    index.resize(k);
    dist2.resize(k);
    const std::size_t n = index_.knnSearch(q.data(), k, index.data(), dist2.data());
    index.resize(n);
    dist2.resize(n);
  }

  /// All points within distance `radius` (not sorted); `found` holds (index, squared distance).
  void within(const Eigen::Vector3d& q, double radius,
              std::vector<std::pair<std::uint32_t, double>>& found) const {
    found.clear();
    nanoflann::SearchParams params;
    params.sorted = false;
    index_.radiusSearch(q.data(), radius * radius, found, params);
  }

 private:
  struct Adaptor {
    const Points& points;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points.rows()); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const {
      return points(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d));
    }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>,
                                                    Adaptor, 3, std::uint32_t>;
  Adaptor adaptor_;
  Index index_;
};

}  // namespace partita::coupling
