#pragma once
// Spatial decomposition of a bed into subdomains (one per process of a DEM spread over several):
// recursive coordinate bisection (RCB) by particle count. The bed's box is cut by a plane normal
// to its longest extent into two boxes whose particle counts are in proportion to the number of
// subdomains each side gets (floor(n / 2) and the rest: any count, not only powers of two), and
// each side again, until every box is one subdomain. Every subdomain is an axis-aligned box; the
// boxes tile the bed's box without gaps or overlaps; a point belongs to the box whose half-open
// ranges [lo, hi) hold it, and a point outside the bed's box belongs to the box that holds it
// moved onto the bed's box (a particle that left the box since the cuts were made keeps an
// owner).
//
// Why bisection and not a regular grid of subdomains: a granular bed is rarely uniform (a filled
// cell beside an empty one, a heap, the region a bow has emptied), and a grid's equal boxes would
// give one process most of the particles. Bisection balances the counts whatever the shape, with
// boxes still (the ghosts a box needs are the particles within a distance of it), and when the
// load drifts the cuts are made again from the particles' positions of the moment.
//
// The cuts depend only on the set of positions, not on their order: a cut lies halfway between
// the k-th and (k+1)-th coordinate in sorted order (k the count the lower side gets), and
// positions equal to a cut go to the upper side with all equal ones, so shuffled input gives the
// same boxes. Where many particles share one coordinate the counts can differ from the targets.
//
// How a DEM spread over subdomains uses it (SubdomainStepper, subdomain.hpp, does all of it over
// a SubdomainTransport: in one process, or one subdomain a rank over MPI with partita::dem_mpi):
//  - on a step when the lists are rebuilt (on every subdomain at once), each subdomain sends the
//    particles whose owner() is another subdomain to that subdomain (System::pack_particles(),
//    then remove_particles()), and appends what it receives (unpack_particles()): the pair
//    histories find their pairs at the build that follows;
//  - ghosts: the particles within the cut-off plus the skin of another box (near(x, 2 R_max +
//    skin)) are copied to that subdomain at each build and their positions and velocities
//    refreshed every step, so that every pair with an owned particle is listed where that
//    particle is owned; a pair between an owned particle and a ghost is evaluated by both owners
//    (the same history on both sides);
//  - sums that do not depend on the split: the force pass adds a particle's contacts in index
//    order, so every subdomain numbers its particles and ghosts in one order (GlobalOrder: by the
//    cell of a fixed grid, then id); wall and mesh forces are still summed per subdomain;
//  - ids handed out at run time (fragments) must be unique over the subdomains (not yet).

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace partita::dem {

class DomainDecomposition {
 public:
  struct Box {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero();
    Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  };

  /// One subdomain, which owns every point.
  DomainDecomposition() = default;
  /// Cuts [lo, hi] into `parts` boxes holding about equal numbers of `positions` (positions
  /// outside [lo, hi] are counted on the side of the cut they lie on). Throws Error unless
  /// parts >= 1 and lo < hi in every direction, or when a position is not finite.
  static DomainDecomposition bisection(const std::vector<Eigen::Vector3d>& positions,
                                       const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                       int parts);

  int parts() const { return static_cast<int>(boxes_.size()); }
  const Box& box(int part) const { return boxes_[static_cast<std::size_t>(part)]; }
  const Box& bounds() const { return bounds_; }

  /// The subdomain that owns point x (a walk down the cuts: O(log parts)).
  int owner(const Eigen::Vector3d& x) const;
  /// The subdomains other than `owner(x)` whose box lies within `distance` of x (distance >= 0):
  /// where a particle at x is a ghost when `distance` is the cut-off plus the skin. Appends to
  /// `out` in ascending order (out is cleared first); no allocation once `out` has room.
  void near(const Eigen::Vector3d& x, double distance, std::vector<int>& out) const;
  /// The distance from x to box `part` (0 inside it).
  double distance(const Eigen::Vector3d& x, int part) const;

 private:
  struct Node {  // an inner node cuts along `axis` at `at`; a leaf (axis < 0) is box `part`
    int axis = -1;
    double at = 0.0;
    int lower = -1, upper = -1;  // children
    int part = 0;
  };
  int split(std::vector<Eigen::Vector3d>& points, std::size_t first, std::size_t last,
            const Box& box, int parts);
  void near(int node, const Eigen::Vector3d& x, double distance, int owner,
            std::vector<int>& out) const;

  Box bounds_;
  std::vector<Box> boxes_{Box{}};
  std::vector<Node> nodes_{Node{}};  // nodes_[0] is the root
};

}  // namespace partita::dem
