#pragma once
// The registries of everything a case file selects by name: solvers, mappers, coupling schemes,
// accelerations, convergence measures. Each entry has a one-line doc and a config::Spec of its
// parameters (for validation and `partita docs`). Registration is explicit:
//   Registries r;
//   coupling::register_builtin(r);       // mappers, schemes, accelerations, measures
//   adapters::register_all(r);           // solvers
//   r.solvers.add("my-solver", "one line", [](const SolverContext& c) { ... }, MySolver::spec());

#include <functional>
#include <memory>
#include <vector>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/coupling/convergence/convergence_measure.hpp"
#include "partita/coupling/coupling_scheme.hpp"
#include "partita/coupling/mapping/mapper.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/registry.hpp"
#include "partita/interface/solver.hpp"

namespace partita::coupling {

struct Registries;

/// What a scheme factory receives: the validated `coupling` section and the built pieces.
struct SchemeContext {
  config::Node config;                     ///< the case's `coupling` section
  const Registries* registries = nullptr;  ///< for accelerations and convergence measures
  std::vector<Participant*> participants;  ///< in scheme order
  std::vector<Exchange*> exchanges;
};

using SchemeFactory = std::function<std::unique_ptr<CouplingScheme>(const SchemeContext&)>;
/// Gets the acceleration's node (a map with `type`), validated against the entry's spec.
using AccelerationFactory = std::function<std::unique_ptr<Acceleration>(const config::Node&)>;
/// Gets one item of `convergence`, validated against the entry's spec.
using ConvergenceFactory = std::function<std::unique_ptr<ConvergenceMeasure>(const config::Node&)>;

struct Registries {
  Registry<SolverFactory> solvers{"solver"};
  Registry<MapperFactory> mappers{"mapper"};
  Registry<SchemeFactory> schemes{"scheme"};
  Registry<AccelerationFactory> accelerations{"acceleration"};
  Registry<ConvergenceFactory> convergence_measures{"convergence measure"};
};

/// Add the built-in mappers, schemes, accelerations and convergence measures (one line each).
void register_builtin(Registries& registries);

}  // namespace partita::coupling
