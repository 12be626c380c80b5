#include "partita/interface/version.hpp"

namespace partita {
const char* version() {
  return PARTITA_VERSION;
}
}  // namespace partita
