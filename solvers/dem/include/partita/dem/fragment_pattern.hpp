#pragma once
// How a broken sphere is replaced: a set of fragments inscribed in it, given for a parent of unit
// radius centred at the origin. Every pattern here has cubic or tetrahedral symmetry, so the
// fragments' centre of mass is the parent's centre and their second moment sum m r r^T is
// isotropic (a rigid rotation of the set has the same angular momentum about every axis).
// Because each fragment lies inside the parent (|c| + rho <= 1), it overlaps any neighbour,
// plane or mesh no more than the parent did (triangle inequality).
//
// Patterns (names as in the case file):
//   equal-4        4 equal spheres at the vertices of a regular tetrahedron, each touching the
//                  parent and the other three: rho = 1/(1 + sqrt(3/2)) = 0.4495 (solid fraction
//                  4 rho^3 = 36.3 % of the parent's volume)
//   equal-6        6 equal spheres at the vertices of a regular octahedron, touching the parent
//                  and their four neighbours: rho = 1/(1 + sqrt(2)) = 0.4142 (42.6 %)
//   apollonian-14  the 6 spheres of equal-6 plus 8 smaller ones in the gaps along the cube
//                  diagonals, each touching the parent and three large ones (rho_s = 0.2301;
//                  52.4 %): an Apollonian-type 14-fragment set as used with this criterion by
//                  Ciantia et al. (Geotechnique 65, 2015)

#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class FragmentPattern {
 public:
  enum class Kind { equal_4, equal_6, apollonian_14 };

  explicit FragmentPattern(Kind kind);
  /// The pattern called `name` (one of names()); throws Error naming the known ones otherwise.
  static FragmentPattern named(const std::string& name);
  static std::vector<std::string> names();

  Kind kind() const { return kind_; }
  std::string name() const;
  int size() const { return static_cast<int>(radius_.size()); }
  /// Centre and radius of fragment k for a unit parent.
  const Eigen::Vector3d& centre(int k) const { return centre_[k]; }
  double radius(int k) const { return radius_[k]; }
  /// Sum of the fragments' volumes over the parent's (the mass the fragments hold).
  double volume_fraction() const;

 private:
  Kind kind_;
  std::vector<Eigen::Vector3d> centre_;
  std::vector<double> radius_;
};

}  // namespace partita::dem
