#pragma once
// The case's "participant.name" keys (a mesh, a quantity), split at the dot.

#include <string>
#include <utility>

#include "partita/interface/config.hpp"

namespace partita::run {

inline std::pair<std::string, std::string> split_dot(const config::Node& n, const char* what) {
  const std::string s = n.as_string();
  const auto dot = s.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == s.size())
    n.fail(std::string("expected ") + what + " written participant." +
           (std::string(what) == "a quantity" ? "quantity" : "mesh") + ", found '" + s + "'");
  return {s.substr(0, dot), s.substr(dot + 1)};
}

}  // namespace partita::run
