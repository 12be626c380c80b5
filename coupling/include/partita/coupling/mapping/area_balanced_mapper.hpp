#pragma once
// area-balanced: consistent mapping of a density (traction, pressure) between two point sets
// that carry point weights (the area each point stands for: cell centres with their cell
// areas, quadrature points with their weights), which also preserves the density's integral.
//
// Interpolating a spiky density (DEM contact tractions live on the few STL cells that particles
// touch) by sampling it at another mesh's quadrature points loses or gains force: the integral
// sum_q w_q t_q differs from sum_i A_i t_i by the sampling error of the spikes. This mapper
// builds weights W (target x source) that satisfy both
//   sum_i W_qi = 1                         (rows: a constant is reproduced exactly)
//   sum_q w_q W_qi = A_i * (sum w / sum A)  (columns: the integral is preserved; exactly when the
//                                           two meshes cover the same area)
// by Sinkhorn balancing (alternate column and row scaling) of Gaussian weights over the k
// nearest source points of each target point, plus each source point's nearest target points
// (so every source value is carried). Lengths scale with the local spacing sqrt(A_i).

#include <memory>

#include "partita/coupling/mapping/sparse_mapper.hpp"

namespace partita::coupling {

class AreaBalancedMapper final : public SparseMapper {
 public:
  AreaBalancedMapper(Constraint constraint, int neighbors)
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
