#pragma once
// The DEM library's error type for user errors (bad input, unstable time step, unknown ids).
// Messages say what was wrong, the value found and what is allowed.

#include <stdexcept>
#include <string>

namespace partita::dem {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error("dem: " + message) {}
};

}  // namespace partita::dem
