#include "partita/coupling/mapping/mapper.hpp"

#include <yaml-cpp/yaml.h>

#include "partita/interface/error.hpp"

namespace partita::coupling {

const char* to_string(Constraint c) {
  return c == Constraint::consistent ? "consistent" : "conservative";
}

void Mapper::set_meshes(const Mesh& from, const Mesh& to) {
  source_size_ = from.size();
  target_size_ = to.size();
  source_name_ = from.name();
  target_name_ = to.name();
}

void Mapper::check_input(const Eigen::MatrixXd& in) const {
  if (source_size_ < 0)
    throw Error("mapper '" + name() +
                "': map() called before compute(); compute the mapping from the meshes first");
  if (in.rows() != source_size_)
    throw Error("mapper '" + name() + "' (" + to_string(constraint()) + ") from mesh '" +
                source_name_ + "' to mesh '" + target_name_ + "': the field has " +
                std::to_string(in.rows()) + " rows but mesh '" + source_name_ + "' has " +
                std::to_string(source_size_) +
                " points; write one row per point of the source mesh");
}

std::string mapper_type(const config::Node& node) {
  if (node.is_scalar()) return node.as_string();
  if (node.is_map()) {
    if (!node.has("type"))
      node.fail(
          "a mapper given as a map needs 'type: <name>' (e.g. {type: rbf, support_radius: "
          "2.0e-3})");
    return node["type"].as_string();
  }
  node.fail(
      "expected a mapper name (e.g. 'nearest-projection') or a map with 'type' and options, "
      "found " +
      node.describe());
}

std::unique_ptr<Mapper> create_mapper(const Registry<MapperFactory>& registry,
                                      const MapperContext& context) {
  const config::Node& node = context.config;
  mapper_type(node);  // throws unless a name or a map with `type`
  const auto& entry = registry.get(node.is_scalar() ? node : node["type"]);
  return entry.factory(context);
}

config::Node mapper_options(const config::Node& node,
                            const std::shared_ptr<const config::Spec>& spec) {
  if (node.is_map()) return node.validated(spec);
  std::string required;
  for (const auto& p : spec->params())
    if (p.is_required()) required += (required.empty() ? "" : ", ") + p.key();
  if (!required.empty())
    node.fail("mapper '" + node.as_string() + "' needs the option(s) " + required +
              "; write the mapper as a map, e.g. {type: " + node.as_string() + ", " +
              spec->params().front().key() + ": ...}");
  // A plain name: an empty map at the same place, so the getters see the declared defaults.
  config::Node empty(YAML::Node(YAML::NodeType::Map),
                     std::make_shared<const std::string>(node.file()), node.path());
  return empty.validated(spec);
}

}  // namespace partita::coupling
