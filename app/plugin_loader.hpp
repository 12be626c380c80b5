#pragma once
// Solver plugins: shared libraries built against the installed partita (partita::plugin) whose
// entry point (PARTITA_PLUGIN, partita/coupling/plugin.hpp) adds solvers to the registries.
// Loaded with dlopen from `--plugin LIB` (every subcommand, repeatable) and from the case's
// `plugins:` list (paths relative to the case file): the command line's first, then the case's;
// a library named twice (same file) loads once; nothing shadows anything: a name that two
// libraries, or a library and partita, register is an error naming both.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "partita/coupling/registries.hpp"

namespace CLI {
class App;
}

namespace partita::app {

class Plugins {
 public:
  /// Plugins add to `registries` (which must outlive this); what is in it now counts as built in.
  explicit Plugins(coupling::Registries& registries);

  /// Load one library; `named_by` says where it was named, for messages ("--plugin", or the
  /// case file's line). Throws partita::Error naming the library: a missing file, dlopen's
  /// message, no entry point, a partita version other than this one, a name registered twice.
  void load(const std::filesystem::path& library, const std::string& named_by);

  /// The --plugin values, in order.
  void load_command_line(const std::vector<std::string>& libraries);

  /// The case file's `plugins:` list (after the --set overrides).
  void load_case(const std::filesystem::path& case_file, const std::vector<std::string>& overrides);

  /// The --plugin libraries as absolute paths, to hand to child runs (a sweep's variants).
  const std::vector<std::string>& command_line() const { return command_line_; }

 private:
  coupling::Registries& registries_;
  std::map<std::string, std::string> origin_;  // "<kind> '<name>'" -> who registered it
  std::vector<std::filesystem::path> loaded_;  // canonical paths
  std::vector<std::string> command_line_;
};

/// Add the repeatable `--plugin LIB` option to a (sub)command; its values go to `libraries`.
void add_plugin_option(CLI::App& command, std::vector<std::string>& libraries);

}  // namespace partita::app
