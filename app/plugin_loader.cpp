#include "plugin_loader.hpp"

#include <dlfcn.h>

#include <cxxabi.h>
#include <cstdlib>
#include <memory>

#include <CLI/CLI.hpp>

#include "partita/adapters/material_law_plugins.hpp"
#include "partita/run/case_run.hpp"
#include "partita/coupling/plugin.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/version.hpp"

namespace partita::app {

namespace fs = std::filesystem;

namespace {

// The same visit over the five registries of two Registries (the plugin's and partita's).
template <class F>
void for_each_pair(coupling::Registries& a, coupling::Registries& b, F&& f) {
  f(a.solvers, b.solvers);
  f(a.mappers, b.mappers);
  f(a.schemes, b.schemes);
  f(a.accelerations, b.accelerations);
  f(a.convergence_measures, b.convergence_measures);
}

template <class R>
std::string key(const R& registry, const std::string& name) {
  return registry.kind() + " '" + name + "'";
}

// dlopen's message with the C++ name of an undefined symbol ("undefined symbol: _ZN7partita...")
// demangled, and what such a symbol usually means.
std::string explain_dlerror(std::string message) {
  const std::string marker = "undefined symbol: ";
  const auto at = message.find(marker);
  if (at == std::string::npos) return message;
  const std::string mangled = message.substr(at + marker.size());
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(
      abi::__cxa_demangle(mangled.c_str(), nullptr, nullptr, &status), std::free);
  if (status == 0 && name) message += " (" + std::string(name.get()) + ")";
  return message +
         "; partita resolves a plugin's partita symbols from this executable: a symbol it lacks "
         "means the plugin was built against other partita headers, or uses a library that it "
         "must link itself";
}

// Whether the library defines partita's own functions itself (it linked partita's static
// libraries) rather than taking them from this executable: probed with the constructor of
// partita::Error, which any code of partita's that throws pulls in, and partita::version().
bool carries_partita(void* handle, void* entry_point) {
  Dl_info plugin{};
  if (!dladdr(entry_point, &plugin)) return false;
  for (const char* name :
       {"_ZN7partita5ErrorC1ERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEE",
        "_ZN7partita5ErrorC2ERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEE",
        "_ZN7partita7versionEv"}) {
    Dl_info where{};
    void* s = dlsym(handle, name);
    if (s && dladdr(s, &where) && where.dli_fbase == plugin.dli_fbase) return true;
  }
  return false;
}

}  // namespace

Plugins::Plugins(coupling::Registries& registries) : registries_(registries) {
  for_each_pair(registries_, registries_, [&](const auto& r, const auto&) {
    for (const auto& e : r.entries()) origin_[key(r, e.name)] = "partita itself (built in)";
  });
}

void Plugins::load(const fs::path& library, const std::string& named_by) {
  const std::string who = "plugin " + library.string() + " (" + named_by + ")";
  std::error_code ec;
  if (!fs::exists(library, ec))
    throw Error(who +
                ": no such file (a plugin is a shared library built against partita, "
                "e.g. build/libmy_solver.so; see partita docs case, key plugins)");
  if (!fs::is_regular_file(library, ec)) throw Error(who + ": not a file");
  const fs::path canonical = fs::canonical(library);
  for (const auto& l : loaded_)
    if (l == canonical) {
      log::get("app")->debug("{}: already loaded", who);
      return;
    }

  dlerror();
  // RTLD_NOW: every symbol is resolved here, so a missing one is this error and not a crash
  // later; RTLD_LOCAL: one plugin's symbols never satisfy another's.
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw Error(who + ": cannot be loaded: " + explain_dlerror(why ? why : "dlopen failed"));
  }
  auto symbol = [&](const char* name) {
    void* s = dlsym(handle, name);
    if (!s) {
      dlclose(handle);
      throw Error(who + ": not a partita plugin: it does not export the function " + name +
                  " (define the entry point with PARTITA_PLUGIN(registries) { ... } from "
                  "partita/coupling/plugin.hpp)");
    }
    return s;
  };
  const auto version_of =
      reinterpret_cast<coupling::PluginVersionFunction>(symbol(PARTITA_PLUGIN_VERSION_SYMBOL));
  const auto register_into =
      reinterpret_cast<coupling::PluginRegisterFunction>(symbol(PARTITA_PLUGIN_REGISTER_SYMBOL));
  const char* text = version_of();
  const std::string built_against = text ? text : "(none)";  // before dlclose unmaps the text
  if (built_against != version()) {
    dlclose(handle);
    throw Error(who + ": built against partita " + built_against + ", but this is partita " +
                version() +
                ": rebuild the plugin against this partita (a plugin shares partita's C++ "
                "classes, so only the version it was built against may load it)");
  }

  if (carries_partita(handle, reinterpret_cast<void*>(register_into))) {
    dlclose(handle);
    throw Error(who +
                ": it carries its own copy of partita's libraries (it links "
                "partita::interface or partita::coupling): link partita::plugin instead, "
                "so that it uses the one partita of the executable that loads it");
  }

  // The plugin registers into registries of its own; they join partita's only when no name
  // clashes. From here on the library stays loaded for the life of the process (its factories
  // live in it).
  coupling::Registries added;
  try {
    register_into(added);
  } catch (const Error& e) {
    throw Error(who + ": " + e.what());
  } catch (const std::exception& e) {
    throw Error(who + ": registering its entries failed: " + e.what());
  }
  for_each_pair(added, registries_, [&](const auto& from, const auto& into) {
    for (const auto& e : from.entries()) {
      const std::string k = key(from, e.name);
      if (into.contains(e.name))
        throw Error(who + ": its " + k + " is already registered by " + origin_.at(k) +
                    "; names must be unique (rename one of them)");
    }
  });
  // material laws of the FE solver: an optional second entry point
  // (partita/adapters/material_laws.hpp), added once the names above are known to be free
  std::vector<std::string> names;
  if (void* laws = dlsym(handle, PARTITA_PLUGIN_MATERIAL_LAWS_SYMBOL))
    for (const auto& law : adapters::add_plugin_material_laws(laws, who))
      names.push_back("material law '" + law + "'");
  for_each_pair(added, registries_, [&](const auto& from, auto& into) {
    for (const auto& e : from.entries()) {
      // the one-line doc says where the entry comes from (partita list, partita docs NAME)
      into.add(e.name, e.doc + " [plugin " + canonical.filename().string() + "]", e.factory, e.spec,
               e.quantities);
      origin_[key(from, e.name)] = "plugin " + canonical.string();
      names.push_back(key(from, e.name));
    }
  });
  loaded_.push_back(canonical);
  if (names.empty())
    log::get("app")->warn("{}: registers nothing", who);
  else
    log::get("app")->debug("{}: {}", who, join_names(names));
}

void Plugins::load_command_line(const std::vector<std::string>& libraries) {
  for (const auto& l : libraries) {
    load(l, "--plugin");
    command_line_.push_back(fs::absolute(l).string());
  }
}

void Plugins::load_case(const fs::path& case_file, const std::vector<std::string>& overrides) {
  for (const auto& p : run::case_plugins(case_file, overrides))
    load(p.library, p.where.location().str() + ": plugins");
}

void add_plugin_option(CLI::App& command, std::vector<std::string>& libraries) {
  command
      .add_option_function<std::vector<std::string>>(
          "--plugin",
          [&libraries](const std::vector<std::string>& v) {
            libraries.insert(libraries.end(), v.begin(), v.end());
          },
          "Load a solver plugin (a shared library built against this partita) before anything "
          "else; repeatable; a case may also list its own (key plugins)")
      ->type_name("LIB")
      ->allow_extra_args(false);
}

}  // namespace partita::app
