#pragma once
// The built-in data mappers, one registry line each (no static self-registration):
//   nearest-neighbor    value of the nearest source point (k-d tree); first order
//   nearest-projection  projection onto the source triangles, barycentric interpolation;
//                       second order. A source without triangles (a cell-centre point cloud)
//                       uses a local linear least-squares fit (option `point_cloud`)
//   rbf                 radial basis functions (compact Wendland C2 by default) with a linear
//                       polynomial, solved with a sparse factorisation

#include "partita/coupling/mapping/mapper.hpp"
#include "partita/interface/registry.hpp"

namespace partita::coupling {

/// Add the built-in mappers to `registry` (each with its config::Spec, for `partita docs`).
void register_mappers(Registry<MapperFactory>& registry);

}  // namespace partita::coupling
