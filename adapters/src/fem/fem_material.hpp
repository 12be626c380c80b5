#pragma once
// The FEM participant's material (YAML `material:`): everything that reads it from a case. Its
// parameter spec (model: linear-elastic | neo-hooke | neo-hooke-decoupled | j2-plasticity |
// j2-plasticity-finite-strain, the elastic constants, the hardening, the failure criterion of
// fem_rupture.hpp), and the model the validated values make of a mesh: the elastic constants
// (fem::Material, read once), the law of a nonlinear model and the failure criterion.

#include <memory>

#include "partita/fem/fem.hpp"
#include "partita/interface/config.hpp"

namespace partita::adapters {

/// The spec of the participant's `material` section.
std::shared_ptr<config::Spec> fem_material_spec();

/// A model of `mesh` made of the case's material (`material`, validated against
/// fem_material_spec()); a law's parameters out of range are errors at their keys.
fem::Model build_fem_model(fem::Mesh mesh, const config::Node& material);

}  // namespace partita::adapters
