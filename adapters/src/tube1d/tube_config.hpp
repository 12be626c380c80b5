#pragma once
// The YAML keys of the tube participants (defaults: the preCICE tutorial values) and the
// parameters they give.

#include <memory>

#include "partita/interface/config.hpp"
#include "partita/tube1d/tube_parameters.hpp"

namespace partita::adapters {

/// The spec of a tube participant; `fluid` adds the flow keys (inlet, initial state).
std::shared_ptr<const config::Spec> tube_spec(const char* name, const char* doc, bool fluid);
/// Parameters from a node validated against tube_spec().
tube1d::TubeParameters tube_parameters(const config::Node& node, bool fluid);

}  // namespace partita::adapters
