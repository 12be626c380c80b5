#pragma once
// Logging: one named spdlog logger per module ("interface", "coupling", "adapters", "app", ...).
// Native solvers do not log (they know no logging library); their adapters do.

#include <memory>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

namespace partita::log {

/// The logger of a module, created on first use with the common pattern and level.
std::shared_ptr<spdlog::logger> get(const std::string& module);

/// Set the level of every partita logger (existing and future ones).
void set_level(spdlog::level::level_enum level);

/// Parse a level name: trace, debug, info, warn, error, critical, off. Unknown -> partita::Error.
spdlog::level::level_enum parse_level(std::string_view name);

/// The names accepted by parse_level().
const char* level_names();

}  // namespace partita::log
