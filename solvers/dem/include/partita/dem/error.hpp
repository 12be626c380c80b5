#pragma once
// The DEM library's error type for user errors (bad input, unstable time step, unknown ids).
// Messages say what was wrong, the value found and what is allowed.

#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

namespace partita::dem {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error("dem: " + message) {}
};

/// "(x, y, z)" for messages.
inline std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

}  // namespace partita::dem
