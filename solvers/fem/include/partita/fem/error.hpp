#pragma once
#include <stdexcept>
#include <string>

namespace partita::fem {

// The one exception type of partita::fem: user errors (bad mesh files, unknown set names,
// singular systems, ...). The message says what was wrong, where, and what is allowed.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace partita::fem
