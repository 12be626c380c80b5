#pragma once
#include <memory>
#include <string>
#include <vector>

#include "partita/fem/dirichlet_condition.hpp"
#include "partita/fem/failure_criterion.hpp"
#include "partita/fem/hex8_formulation.hpp"
#include "partita/fem/load.hpp"
#include "partita/fem/material.hpp"
#include "partita/fem/material_law.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem {

// What is computed: mesh + material(s) + Dirichlet conditions + model loads. A StructuralSolver
// takes a copy, so change a Model before building its StructuralSolver. Names are checked when they
// are given (Error listing the known sets / faces / regions).
class Model {
 public:
  explicit Model(Mesh mesh, const Material& material = {});

  const Mesh& mesh() const { return mesh_; }

  // --- material: one law per region ---
  // A linear-elastic material for every region / one region: a LinearElasticLaw of it.
  void set_material(const Material& material);
  void set_material(const std::string& region, const Material& material);
  // A constitutive law (linear-elastic, neo-hooke, j2-plasticity, ...) for every region / one
  // region.
  void set_material_law(std::shared_ptr<const MaterialLaw> law);
  void set_material_law(const std::string& region, std::shared_ptr<const MaterialLaw> law);
  // The law of a region (a linear-elastic region's is its LinearElasticLaw).
  const MaterialLaw& law(int region) const { return *laws_.at(static_cast<std::size_t>(region)); }
  // The law of a region, or nullptr when the region is linear elastic (its material(region)
  // is all the linear path needs).
  const MaterialLaw* material_law(int region) const {
    const auto r = static_cast<std::size_t>(region);
    return linear_.at(r) ? nullptr : laws_[r].get();
  }
  // The region's small-strain constants, a view of its law (MaterialLaw::small_strain_material:
  // a linear-elastic law's Material, a built-in nonlinear law's E, nu and rho): what the solver
  // reads for the linear path's stiffness and stresses, the explicit stable step and contact.
  const Material& material(int region) const {
    return materials_.at(static_cast<std::size_t>(region));
  }
  // True when every region is linear elastic: the solver's factorise-once path applies.
  bool is_linear() const;
  double density(int region) const { return law(region).density(); }
  // Rupture: a failure criterion for every region / one region (none by default; see
  // FailureCriterion). Needs a law with plastic strain (j2-plasticity) to ever fail.
  void set_failure_criterion(const FailureCriterion& criterion);
  void set_failure_criterion(const std::string& region, const FailureCriterion& criterion);
  const FailureCriterion& failure_criterion(int region) const {
    return failure_.at(static_cast<std::size_t>(region));
  }
  void set_hex8_formulation(Hex8Formulation f) { hex8_ = f; }
  Hex8Formulation hex8_formulation() const { return hex8_; }

  // --- Dirichlet conditions (components 0 = x, 1 = y, 2 = z) ---
  void fix(const std::string& node_set, const std::vector<int>& components = {0, 1, 2});
  // u_c(t) = value(t) on every node of the set.
  void prescribe(const std::string& node_set, int component, TimeFunction value);
  // u_c(X, t) = value(X, t), X the node's reference position.
  void prescribe_field(const std::string& node_set, int component, SpaceTimeFunction value);
  const std::vector<DirichletCondition>& dirichlet_conditions() const { return dirichlet_; }

  // --- model loads, each times amplitude(t) (1 when empty) ---
  void add_pressure(const std::string& face, double pressure, TimeFunction amplitude = {});
  void add_traction(const std::string& face, const Vec3& traction, TimeFunction amplitude = {});
  void add_nodal_force(const std::string& node_set, const Vec3& force_per_node,
                       TimeFunction amplitude = {});
  void add_gravity(const Vec3& acceleration, TimeFunction amplitude = {});
  const std::vector<Load>& loads() const { return loads_; }

 private:
  void check_component(int component) const;
  void assign(std::size_t region, std::shared_ptr<const MaterialLaw> law);
  Mesh mesh_;
  std::vector<std::shared_ptr<const MaterialLaw>> laws_;  // per region, never null
  // derived from laws_ by assign(), never set alone: whether each is a LinearElasticLaw, and its
  // small-strain constants
  std::vector<char> linear_;
  std::vector<Material> materials_;
  std::vector<FailureCriterion> failure_;                 // per region
  Hex8Formulation hex8_ = Hex8Formulation::IncompatibleModes;
  std::vector<DirichletCondition> dirichlet_;
  std::vector<Load> loads_;
};

}  // namespace partita::fem
