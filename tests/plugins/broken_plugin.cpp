// Plugins that partita must refuse, each with a clear error naming the library
// (tests/app/test_plugins.cpp). One source, one variant per definition:
//   PLUGIN_OTHER_VERSION   built against "another" partita version
//   PLUGIN_NO_ENTRY        a shared library without the entry point
//   PLUGIN_BUILTIN_NAME    registers a mapper under a built-in name (nearest-neighbor)
//   PLUGIN_THROWS          its registration throws partita::Error
//   PLUGIN_OWN_COPY        links partita's static libraries (a second copy of partita)
#include "partita/coupling/plugin.hpp"
#include "partita/interface/error.hpp"

#if defined(PLUGIN_OTHER_VERSION)
extern "C" __attribute__((visibility("default"))) const char* partita_plugin_api_version() {
  return "0.0.0-other";
}
extern "C" __attribute__((visibility("default"))) void partita_register_plugin(
    partita::coupling::Registries&) {}
#elif defined(PLUGIN_NO_ENTRY)
extern "C" __attribute__((visibility("default"))) int not_a_partita_plugin() {
  return 1;
}
#elif defined(PLUGIN_BUILTIN_NAME)
PARTITA_PLUGIN(registries) {
  registries.mappers.add("nearest-neighbor", "a second mapper of that name",
                         partita::coupling::MapperFactory{});
}
#elif defined(PLUGIN_THROWS) || defined(PLUGIN_OWN_COPY)
PARTITA_PLUGIN(registries) {
  throw partita::Error("the plugin's own message: its licence file is missing");
}
#endif
