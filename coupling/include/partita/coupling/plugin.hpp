#pragma once
// The entry point of a solver plugin: a shared library, built out of tree against the installed
// partita (find_package(partita), target partita::plugin), that the stock `partita` executable
// loads with `--plugin lib.so` or a case's `plugins:` list. One source file of the library says
//
//   #include "partita/coupling/plugin.hpp"
//   PARTITA_PLUGIN(registries) {
//     registries.solvers.add("oscillator", "a mass on a spring along z", OscillatorAdapter::create,
//                            OscillatorAdapter::spec(), OscillatorAdapter::quantities());
//   }
//
// which defines two C functions (the only symbols partita looks up in the library):
//   const char* partita_plugin_api_version()      the partita version the plugin was built
//                                                 against (PARTITA_VERSION_STRING);
//   void partita_register_plugin(Registries&)     adds its entries (solvers, and if it likes
//                                                 mappers, schemes, ...) to a registry of its own,
//                                                 which partita then merges into its registries.
// The ABI rule: a plugin is C++ that shares partita's classes (Solver, Spec, Registry, ...), so it
// is loaded only by the partita version it was built against (the same version string; a
// different one is refused with both versions named) and must be built with the same compiler
// family and standard library. It links partita::plugin only (the headers and the shared
// third-party libraries), never partita's static libraries: partita's own symbols resolve from
// the executable at load time, so the plugin's solver lives in the executable's registries and
// uses its one copy of everything (README: "Writing an adapter as a plugin").

#include "partita/coupling/registries.hpp"
#include "partita/interface/version_number.hpp"

/// The names partita looks up with dlsym.
#define PARTITA_PLUGIN_VERSION_SYMBOL "partita_plugin_api_version"
#define PARTITA_PLUGIN_REGISTER_SYMBOL "partita_register_plugin"

/// Define the plugin's entry point; the braces that follow are its body, `registries_name` a
/// partita::coupling::Registries& to add entries to.
#define PARTITA_PLUGIN(registries_name)                                                      \
  extern "C" __attribute__((visibility("default"))) const char* partita_plugin_api_version() { \
    return PARTITA_VERSION_STRING;                                                           \
  }                                                                                          \
  extern "C" __attribute__((visibility("default"))) void partita_register_plugin(            \
      partita::coupling::Registries& registries_name)

namespace partita::coupling {
/// The types of the two entry points, for the loader.
using PluginVersionFunction = const char* (*)();
using PluginRegisterFunction = void (*)(Registries&);
}  // namespace partita::coupling
