#include "partita/fem/operator_contribution.hpp"

#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

const std::vector<double>& OperatorContribution::committed_state() const {
  static const std::vector<double> kNone;
  return kNone;
}

void OperatorContribution::set_committed_state(const std::vector<double>& state) {
  if (!state.empty()) {
    throw Error("operator contribution '" + std::string(name()) + "': a state of " +
                std::to_string(state.size()) + " values was given, it keeps none");
  }
}

}  // namespace partita::fem
