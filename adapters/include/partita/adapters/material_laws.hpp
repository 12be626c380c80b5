#pragma once
// The material laws the FEM adapter builds from a case's `material: {model: ...}`: the FE
// solver's built-in laws (fem::register_material_laws) and those plugins add. A plugin adds laws
// with a second entry point beside PARTITA_PLUGIN (docs/extending.md):
//
//   #include "partita/adapters/material_laws.hpp"
//   PARTITA_PLUGIN_MATERIAL_LAWS(laws) { laws.add(my_law_entry()); }
//
// which defines the C function partita_register_material_laws(fem::MaterialLawRegistry&): the
// loader calls it with a registry of the plugin's own and adds its entries to material_laws()
// when no name clashes.

#include "partita/fem/material_law_registry.hpp"

#include "partita/adapters/material_law_plugins.hpp"

/// Define a plugin's material-law entry point; `laws_name` is a partita::fem::MaterialLawRegistry&.
#define PARTITA_PLUGIN_MATERIAL_LAWS(laws_name)                                   \
  extern "C" __attribute__((visibility("default"))) void                          \
  partita_register_material_laws(partita::fem::MaterialLawRegistry& laws_name)

namespace partita::adapters {

/// The type of the entry point.
using MaterialLawsFunction = void (*)(fem::MaterialLawRegistry&);

/// The laws of this process: the built-in ones on first use, then those plugins added.
fem::MaterialLawRegistry& material_laws();

}  // namespace partita::adapters
