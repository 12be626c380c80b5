#pragma once
// The FEM participant's material (YAML `material:`): everything that reads it from a case. Its
// parameter spec, made from the material-law registry (material_laws(): the FE solver's built-in
// laws and those plugins add): `model` is one of the registry's names and each law's parameters
// are the section's keys (those of some laws only say which), beside the failure criterion of
// fem_rupture.hpp; and the model the validated values make of a mesh: the law's parameters read
// once into fem::MaterialParameters, its entry's checks placed at their keys, the law its factory
// builds, and the failure criterion.

#include <memory>

#include "partita/fem/fem.hpp"
#include "partita/interface/config.hpp"

namespace partita::adapters {

/// The spec of the participant's `material` section: one object for the process, which
/// refresh_fem_material_spec() brings up to date with material_laws().
std::shared_ptr<config::Spec> fem_material_spec();

/// Rebuild the spec above in place from material_laws() (after a plugin added laws), so that
/// the FEM spec that holds it validates and documents the new laws and their keys.
void refresh_fem_material_spec();

/// A model of `mesh` made of the case's material (`material`, validated against
/// fem_material_spec()); a law's parameters out of range or breaking a rule between them are
/// errors at their keys.
fem::Model build_fem_model(fem::Mesh mesh, const config::Node& material);

}  // namespace partita::adapters
