#include "partita/adapters/material_law_plugins.hpp"

#include "partita/interface/error.hpp"

#ifdef PARTITA_HAVE_FEM
#include "fem_material.hpp"
#include "partita/adapters/material_laws.hpp"
#include "partita/fem/error.hpp"
#endif

namespace partita::adapters {

#ifdef PARTITA_HAVE_FEM

namespace {

std::string describe(const fem::MaterialParameter& d) {
  if (!d.is_table()) return d.unit.empty() ? "a number without unit" : "a number in " + d.unit;
  std::string s = "a table of rows (";
  for (std::size_t i = 0; i < d.columns.size(); ++i)
    s += (i == 0 ? "" : ", ") + d.columns[i].name +
         (d.columns[i].unit.empty() ? "" : " [" + d.columns[i].unit + "]");
  return s + ")";
}

// Why a law's parameters cannot be keys of the material section beside the known laws' ("" when
// they can): a key of the section is one thing in one unit whichever law takes it, and `model`
// and `failure` are the section's own.
std::string key_clash(const fem::MaterialLawRegistry& laws, const fem::MaterialLawEntry& entry) {
  for (const auto& d : entry.parameters) {
    if (d.name == "model" || d.name == "failure")
      return "parameter '" + d.name +
             "' is a key of the material section itself (the law's name, the rupture criterion); "
             "rename the parameter";
    for (const auto& other : laws.entries()) {
      const fem::MaterialParameter* o = other.find(d.name);
      if (o == nullptr || describe(*o) == describe(d)) continue;
      return "parameter '" + d.name + "' is " + describe(d) + ", but material law '" +
             other.name + "' declares it as " + describe(*o) +
             "; a key of the material section means one thing in one unit (rename the "
             "parameter)";
    }
  }
  return "";
}

}  // namespace

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
  for (const auto& entry : added.entries()) {
    if (laws.find(entry.name) != nullptr)
      throw Error(who + ": its material law '" + entry.name +
                  "' is already registered (built in or by an earlier plugin); names must be "
                  "unique (rename one of them)");
    if (const std::string clash = key_clash(laws, entry); !clash.empty())
      throw Error(who + ": its material law '" + entry.name + "': " + clash);
  }
  std::vector<std::string> names;
  for (const auto& entry : added.entries()) {
    laws.add(entry);
    names.push_back(entry.name);
  }
  refresh_fem_material_spec();  // the FEM's material section: the new laws and their keys
  return names;
}

#else

std::vector<std::string> add_plugin_material_laws(void*, const std::string& who) {
  throw Error(who + ": it adds material laws, but this build of partita has no FE solver");
}

#endif

}  // namespace partita::adapters
