#include "partita/coupling/mapping/register_mappers.hpp"

#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"

namespace partita::coupling {

void register_mappers(Registry<MapperFactory>& registry) {
  registry.add("nearest-neighbor", "value of the nearest source point (k-d tree); first order",
               NearestNeighborMapper::create, NearestNeighborMapper::spec());
}

}  // namespace partita::coupling
