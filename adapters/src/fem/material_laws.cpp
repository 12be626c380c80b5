#include "partita/adapters/material_law_plugins.hpp"

#include "partita/interface/error.hpp"

#ifdef PARTITA_HAVE_FEM
#include "partita/adapters/material_laws.hpp"
#include "partita/fem/error.hpp"
#endif

namespace partita::adapters {

#ifdef PARTITA_HAVE_FEM

fem::MaterialLawRegistry& material_laws() {
  // the FE library's explicit list on first use; plugins add to it when they are loaded
  static fem::MaterialLawRegistry laws = [] {
    fem::MaterialLawRegistry r;
    fem::register_material_laws(r);
    return r;
  }();
  return laws;
}

std::vector<std::string> add_plugin_material_laws(void* entry_point, const std::string& who) {
  fem::MaterialLawRegistry added;
  try {
    reinterpret_cast<MaterialLawsFunction>(entry_point)(added);
  } catch (const std::exception& e) {
    throw Error(who + ": registering its material laws failed: " + e.what());
  }
  fem::MaterialLawRegistry& laws = material_laws();
  for (const auto& entry : added.entries())
    if (laws.find(entry.name) != nullptr)
      throw Error(who + ": its material law '" + entry.name +
                  "' is already registered (built in or by an earlier plugin); names must be "
                  "unique (rename one of them)");
  std::vector<std::string> names;
  for (const auto& entry : added.entries()) {
    laws.add(entry);
    names.push_back(entry.name);
  }
  return names;
}

#else

std::vector<std::string> add_plugin_material_laws(void*, const std::string& who) {
  throw Error(who + ": it adds material laws, but this build of partita has no FE solver");
}

#endif

}  // namespace partita::adapters
