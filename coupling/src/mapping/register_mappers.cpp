#include "partita/coupling/mapping/register_mappers.hpp"

#include "partita/coupling/mapping/area_balanced_mapper.hpp"
#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"
#include "partita/coupling/mapping/nearest_projection_mapper.hpp"
#include "partita/coupling/mapping/rbf_mapper.hpp"

namespace partita::coupling {

void register_mappers(Registry<MapperFactory>& registry) {
  registry.add("nearest-neighbor", "value of the nearest source point (k-d tree); first order",
               NearestNeighborMapper::create, NearestNeighborMapper::spec());
  registry.add("nearest-projection",
               "projection onto the source triangles, barycentric; second order (point clouds: "
               "local linear fit)",
               NearestProjectionMapper::create, NearestProjectionMapper::spec());
  registry.add(
      "rbf",
      "radial basis functions + linear polynomial (compact Wendland C2, sparse factorisation)",
      RbfMapper::create, RbfMapper::spec());
  registry.add("area-balanced",
               "densities between weighted point sets (cell centres <-> quadrature points): "
               "consistent and integral-preserving to round-off (exact bisection of the weights)",
               AreaBalancedMapper::create, AreaBalancedMapper::spec());
}

}  // namespace partita::coupling
