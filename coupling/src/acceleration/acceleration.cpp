#include "partita/coupling/acceleration/acceleration.hpp"

#include "partita/interface/config.hpp"

namespace partita::coupling {

void declare_accelerated_data(config::Spec& spec) {
  spec.strings("data",
               "the data fields to accelerate (default: what the last participant in order "
               "writes, or every exchange for parallel schemes)");
}

}  // namespace partita::coupling
