#include "partita/fem/model.hpp"

#include <algorithm>

#include "partita/fem/error.hpp"
#include "partita/fem/linear_elastic_law.hpp"

namespace partita::fem {

Model::Model(Mesh mesh, const Material& material) : mesh_(std::move(mesh)) {
  mesh_.validate();
  const std::size_t regions = std::max<std::size_t>(1, mesh_.region_names().size());
  laws_.resize(regions);
  linear_.resize(regions);
  materials_.resize(regions);
  set_material(material);
  failure_.assign(regions, FailureCriterion{});
}

void Model::assign(std::size_t region, std::shared_ptr<const MaterialLaw> law) {
  linear_.at(region) = dynamic_cast<const LinearElasticLaw*>(law.get()) != nullptr;
  materials_.at(region) = law->small_strain_material();
  laws_.at(region) = std::move(law);
}

void Model::set_failure_criterion(const FailureCriterion& criterion) {
  std::fill(failure_.begin(), failure_.end(), criterion);
}

void Model::set_failure_criterion(const std::string& region, const FailureCriterion& criterion) {
  failure_.at(static_cast<std::size_t>(mesh_.region(region))) = criterion;
}

void Model::set_material(const Material& material) {
  set_material_law(std::make_shared<LinearElasticLaw>(material));  // validates
}

void Model::set_material(const std::string& region, const Material& material) {
  set_material_law(region, std::make_shared<LinearElasticLaw>(material));
}

void Model::set_material_law(std::shared_ptr<const MaterialLaw> law) {
  if (!law) throw Error("set_material_law: null law");
  for (std::size_t r = 0; r < laws_.size(); ++r) assign(r, law);
}

void Model::set_material_law(const std::string& region, std::shared_ptr<const MaterialLaw> law) {
  if (!law) throw Error("set_material_law('" + region + "'): null law");
  assign(static_cast<std::size_t>(mesh_.region(region)), std::move(law));
}

bool Model::is_linear() const {
  return std::all_of(linear_.begin(), linear_.end(), [](char l) { return l != 0; });
}

void Model::check_component(int component) const {
  if (component < 0 || component > 2) {
    throw Error("displacement component " + std::to_string(component) +
                " does not exist; allowed: 0 (x), 1 (y), 2 (z)");
  }
}

void Model::fix(const std::string& node_set, const std::vector<int>& components) {
  mesh_.node_set(node_set);  // throws for unknown names
  for (int c : components) {
    check_component(c);
    dirichlet_.push_back({node_set, c, {}});
  }
}

void Model::prescribe(const std::string& node_set, int component, TimeFunction value) {
  mesh_.node_set(node_set);
  check_component(component);
  if (!value) throw Error("prescribe('" + node_set + "'): empty function");
  dirichlet_.push_back({node_set, component, [value](const Vec3&, double t) { return value(t); }});
}

void Model::prescribe_field(const std::string& node_set, int component, SpaceTimeFunction value) {
  mesh_.node_set(node_set);
  check_component(component);
  if (!value) throw Error("prescribe_field('" + node_set + "'): empty function");
  dirichlet_.push_back({node_set, component, std::move(value)});
}

void Model::add_pressure(const std::string& face, double pressure, TimeFunction amplitude) {
  mesh_.face(face);
  loads_.push_back({LoadKind::Pressure, face, pressure, Vec3::Zero(), std::move(amplitude)});
}

void Model::add_traction(const std::string& face, const Vec3& traction, TimeFunction amplitude) {
  mesh_.face(face);
  loads_.push_back({LoadKind::Traction, face, 0.0, traction, std::move(amplitude)});
}

void Model::add_nodal_force(const std::string& node_set, const Vec3& force_per_node,
                            TimeFunction amplitude) {
  mesh_.node_set(node_set);
  loads_.push_back({LoadKind::NodalForce, node_set, 0.0, force_per_node, std::move(amplitude)});
}

void Model::add_gravity(const Vec3& acceleration, TimeFunction amplitude) {
  loads_.push_back({LoadKind::Gravity, "", 0.0, acceleration, std::move(amplitude)});
}

}  // namespace partita::fem
