#include "partita/coupling/energy_balance.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace partita::coupling {

const char* role_name(EnergyBalance::Role r) {
  switch (r) {
    case EnergyBalance::Role::input:
      return "input";
    case EnergyBalance::Role::stored:
      return "stored";
    case EnergyBalance::Role::dissipated:
      return "dissipated";
  }
  return "?";
}

EnergyBalance::EnergyBalance(std::vector<Term> terms, Settings settings)
    : terms_(std::move(terms)), settings_(settings) {}

std::vector<std::pair<std::string, std::string>> EnergyBalance::columns() const {
  std::vector<std::pair<std::string, std::string>> c;
  for (const Term& t : terms_)
    c.emplace_back(std::string(role_name(t.role)) + " " + t.participant + "." + t.quantity, t.unit);
  if (settings_.coupling_column)
    c.emplace_back(settings_.count_coupling ? "input coupling created" : "coupling created", "J");
  c.emplace_back("initial", "J");
  c.emplace_back("inputs", "J");
  c.emplace_back("stored + dissipated", "J");
  c.emplace_back("energy balance error", "-");
  return c;
}

EnergyBalance::Row EnergyBalance::evaluate(const std::vector<double>& values,
                                           double coupling_created, std::vector<double>& row) {
  double inputs = 0.0, held = 0.0, input_scale = 0.0, held_scale = 0.0;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const double v = values[i];
    if (terms_[i].role == Role::input) {
      inputs += v;
      input_scale += abs_value(v);
    } else {
      held += v;
      held_scale += abs_value(v);
    }
  }
  if (settings_.count_coupling) {
    inputs += coupling_created;
    input_scale += abs_value(coupling_created);
  }
  if (!started_) {
    initial_ = held - inputs;
    started_ = true;
  }
  Row r;
  r.inputs = inputs;
  r.stored_dissipated = held;
  r.measured = std::max(input_scale, held_scale);
  r.scale = std::max(r.measured, settings_.floor);
  r.error = r.scale > 0.0 ? (held - inputs - initial_) / r.scale : 0.0;
  row.assign(values.begin(), values.end());
  if (settings_.coupling_column) row.push_back(coupling_created);
  row.insert(row.end(), {initial_, inputs, held, r.error});
  return r;
}

std::string EnergyBalance::describe(const Row& r) const {
  return fmt::format(
      "stored + dissipated {:.6g} J against inputs {:.6g} J and the initial {:.6g} J: off by "
      "{:.4g} J, {:.3g} of the scale {:.6g} J",
      r.stored_dissipated, r.inputs, initial_, r.stored_dissipated - r.inputs - initial_, r.error,
      r.scale);
}

}  // namespace partita::coupling
