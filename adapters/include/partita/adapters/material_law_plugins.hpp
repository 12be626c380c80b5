#pragma once
// The plugin loader's side of material laws from plugins (material_laws.hpp is the plugin's):
// no FE header needed to call it.

#include <string>
#include <vector>

/// The name partita looks up with dlsym (optional: a plugin without laws does not define it).
#define PARTITA_PLUGIN_MATERIAL_LAWS_SYMBOL "partita_register_material_laws"

namespace partita::adapters {

/// Calls a plugin's material-law entry point (the function dlsym found under the name above)
/// with a registry of its own, then adds its laws to material_laws() when none of their names
/// is taken; returns the names added. Throws partita::Error naming `who` on a clash, when the
/// entry point throws, or when this build has no FE solver.
std::vector<std::string> add_plugin_material_laws(void* entry_point, const std::string& who);

}  // namespace partita::adapters
