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

void gather_committed_states(const std::vector<std::unique_ptr<OperatorContribution>>& contributions,
                             std::vector<double>& state) {
  state.clear();
  for (const auto& c : contributions) {
    const auto& s = c->committed_state();
    state.insert(state.end(), s.begin(), s.end());
  }
}

void scatter_committed_states(const std::vector<std::unique_ptr<OperatorContribution>>& contributions,
                              const std::vector<double>& state, std::string_view owner) {
  std::size_t total = 0;
  for (const auto& c : contributions) total += c->committed_state().size();
  if (state.size() != total) {
    throw Error(std::string(owner) + ": a state of " + std::to_string(state.size()) +
                " values was given, this model's contributions have " + std::to_string(total) +
                " (state of another model?)");
  }
  std::size_t at = 0;
  for (const auto& c : contributions) {
    const std::size_t n = c->committed_state().size();
    c->set_committed_state(std::vector<double>(state.begin() + static_cast<std::ptrdiff_t>(at),
                                               state.begin() + static_cast<std::ptrdiff_t>(at + n)));
    at += n;
  }
}

}  // namespace partita::fem
