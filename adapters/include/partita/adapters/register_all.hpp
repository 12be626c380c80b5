#pragma once
// Every adapter's solver, registered by name (one line per solver in adapters.cpp).
//   coupling::Registries r;
//   coupling::register_builtin(r);
//   adapters::register_all(r);

#include "partita/coupling/registries.hpp"

namespace partita::adapters {

/// Add the solvers of every adapter built into this library to `registries.solvers`.
void register_all(coupling::Registries& registries);

}  // namespace partita::adapters
