// partita with one more solver: the stock commands for cases that use it, and its contract check.
#include <iostream>

#include "oscillator_adapter.hpp"
#include "partita/adapters/register_all.hpp"
#include "partita/run/case_run.hpp"
#include "partita/interface/conformance.hpp"

int main(int argc, char** argv) try {
  partita::coupling::Registries registries;
  partita::coupling::register_builtin(registries);  // mappers, schemes, accelerations, ...
  partita::adapters::register_all(registries);      // the built-in solvers: dem, fem, tube1d
  OscillatorAdapter::register_in(registries.solvers);
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "conformance") {
    const auto failures = partita::check_solver_contract(
        *registries.solvers.find("oscillator"), "solver: oscillator\nmass: 2\nstiffness: 50\n",
        ".", "conformance");
    for (const auto& f : failures) std::cerr << f << "\n";
    std::cout << "conformance: " << failures.size() << " failures\n";
    return failures.empty() ? 0 : 1;
  }
  if (command != "run" || argc < 3) return std::cerr << "usage: run CASE.yaml [DIR] | conformance\n", 2;
  partita::run::RunOptions options;
  if (argc > 3) options.output_dir = argv[3];
  partita::run::CaseRun run(argv[2], registries, options);
  run.run();
  return 0;
} catch (const partita::Error& e) {
  std::cerr << "error: " << e.what() << "\n";
  return 1;
}
