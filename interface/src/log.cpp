#include "partita/interface/log.hpp"

#include <cstdlib>
#include <mutex>
#include <string_view>
#include <vector>

#include <spdlog/sinks/stdout_color_sinks.h>

#include "partita/interface/error.hpp"

namespace partita::log {

namespace {
// The starting level: info, or PARTITA_LOG_LEVEL from the environment when it names a level
// (the test suite sets warn; a command-line --log-level overrides both).
spdlog::level::level_enum initial_level() {
  const char* env = std::getenv("PARTITA_LOG_LEVEL");
  if (env == nullptr) return spdlog::level::info;
  try {
    return parse_level(env);
  } catch (const Error&) {
    return spdlog::level::info;  // reported by the first get(), where a logger exists
  }
}
struct State {
  std::mutex mutex;
  spdlog::level::level_enum level = initial_level();
  bool env_reported = false;
  spdlog::sink_ptr sink;
};
State& state() {
  static State s;
  return s;
}
}  // namespace

std::shared_ptr<spdlog::logger> get(const std::string& module) {
  State& s = state();
  std::lock_guard<std::mutex> lock(s.mutex);
  if (auto existing = spdlog::get(module)) return existing;
  if (!s.sink) s.sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto logger = std::make_shared<spdlog::logger>(module, s.sink);
  logger->set_pattern("[%H:%M:%S.%e] [%n] %^%l%$: %v");
  logger->set_level(s.level);
  spdlog::register_logger(logger);
  if (!s.env_reported) {
    s.env_reported = true;
    const char* env = std::getenv("PARTITA_LOG_LEVEL");
    bool bad = false;
    try {
      if (env != nullptr) (void)parse_level(env);
    } catch (const Error&) {
      bad = true;
    }
    if (bad)
      logger->warn("PARTITA_LOG_LEVEL='{}' is not a log level (allowed: {}); using info", env,
                   level_names());
  }
  return logger;
}

void set_level(spdlog::level::level_enum level) {
  State& s = state();
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.level = level;
  }
  spdlog::apply_all([level](const std::shared_ptr<spdlog::logger>& l) { l->set_level(level); });
}

const char* level_names() {
  return "trace, debug, info, warn, error, critical, off";
}

spdlog::level::level_enum parse_level(std::string_view name) {
  static const std::vector<std::pair<std::string, spdlog::level::level_enum>> levels = {
      {"trace", spdlog::level::trace}, {"debug", spdlog::level::debug},
      {"info", spdlog::level::info},   {"warn", spdlog::level::warn},
      {"error", spdlog::level::err},   {"critical", spdlog::level::critical},
      {"off", spdlog::level::off}};
  std::vector<std::string> names;
  for (const auto& [n, l] : levels) {
    if (n == name) return l;
    names.push_back(n);
  }
  throw Error("unknown log level '" + std::string(name) + "'; allowed: " + join_names(names) +
              did_you_mean(name, names));
}

}  // namespace partita::log
