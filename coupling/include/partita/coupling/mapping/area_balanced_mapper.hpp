#pragma once
// area-balanced: consistent mapping of a density (traction, pressure) between two point sets
// that carry point weights (the area each point stands for: cell centres with their cell
// areas, quadrature points with their weights), which also preserves the density's integral.
//
// Interpolating a spiky density (DEM contact tractions live on the few STL cells that particles
// touch) by sampling it at another mesh's quadrature points loses or gains force: the integral
// sum_q w_q t_q differs from sum_i A_i t_i by the sampling error of the spikes. This mapper
// builds weights W (target x source) with W >= 0 and
//   sum_i W_qi = 1                         (rows: a constant is reproduced exactly)
//   sum_q w_q W_qi = A_i * (sum w / sum A)  (columns: the integral is preserved; exactly when the
//                                           two meshes cover the same area)
// both to round-off at any size (measured at 10^5 cells: 8e-16 relative, rows and columns), by
// construction.
//
// Construction: P = diag(w) W is a transport plan that moves each target point's weight w_q
// onto source points, c_i = A_i sum(w)/sum(A) onto source point i. It is built by recursive
// bisection: cut the bounding box of the points across its longest side so that each side
// holds half of the target weight, and cut the source points along the same axis at half of
// theirs (the one point of each set that straddles a cut is split between the two sides); repeat
// on both halves until one side has a single point, which then takes the others' weights. On
// meshes that cover the same surface the two cuts of equal weight lie within about a point
// spacing of each other, so each target point draws on the source points it overlaps (entries at
// most 1.6 coarse spacings apart, about 2.3 per row, on the seed's plate at 10^5 cells). No
// iteration, nothing to converge; set-up O(n log^2 n) (0.2 s per 10^5 cells). The totals are
// summed in long double: the plan can be no closer to w and c than the two totals agree.
//
// Option `neighbors` k > 1 then smooths over each source point's k nearest source points:
// W = W_bisection S with S_ij = e_ij / c_i (j != i), S_ii = 1 - sum_j e_ij / c_i, symmetric
// e_ij = 0.5 min(c_i / deg_i, c_j / deg_j) on the symmetric k-nearest graph; S 1 = 1 and
// c^T S = c^T, so both properties hold for W, and S_ii >= 1/2 keeps W >= 0. k = 1 (the default):
// no smoothing, the fewest entries (the cheapest map).
//
// Diagnosis: if more than 1 % of the weight moves farther than 4 point spacings, the two meshes
// do not cover the same surface; the mapper warns at set-up.

#include <memory>

#include "partita/coupling/mapping/sparse_mapper.hpp"

namespace partita::coupling {

class AreaBalancedMapper final : public SparseMapper {
 public:
  AreaBalancedMapper(Constraint constraint, int neighbors = 1)
      : SparseMapper(constraint), neighbors_(neighbors) {}

  std::string name() const override { return "area-balanced"; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Mapper> create(const MapperContext& context);

 protected:
  Matrix interpolation(const Mesh& source, const Mesh& target) const override;

 private:
  int neighbors_;
};

}  // namespace partita::coupling
