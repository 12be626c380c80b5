#pragma once
// Mappers as the case file chooses them: the `mapper` node parsed from YAML, looked up in a
// registry filled by register_mappers().

#include <memory>
#include <string>

#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/mapping/register_mappers.hpp"

namespace partita::coupling::test {

inline const Registry<MapperFactory>& mapper_registry() {
  static const Registry<MapperFactory> registry = [] {
    Registry<MapperFactory> r("mapper");
    register_mappers(r);
    return r;
  }();
  return registry;
}

/// `yaml` is what follows `mapper:` in a case file, e.g. "nearest-projection" or
/// "{type: rbf, support_radius: 3 mm}".
inline std::unique_ptr<Mapper> make_mapper(const std::string& yaml, Constraint constraint) {
  const config::Node node =
      config::Node::load_string("mapper: " + yaml + "\n", "case.yaml")["mapper"];
  return create_mapper(mapper_registry(), MapperContext{node, constraint});
}

}  // namespace partita::coupling::test
