#pragma once
// The Solver contract as a check any adapter can run, in tree or out of tree (installed with
// the package): build the solver from a sample configuration through its registry entry, then
//   - meshes() is non-empty, each mesh named, with points and with data of positive width;
//   - stable_time_step() > 0 and time() starts at 0;
//   - write() gives N x C finite values for every written field;
//   - checkpoint / restore: the same window repeated gives bit-identical outputs and time;
//   - restart (where supports_restart()): a fresh solver read from what this one wrote continues
//     bit for bit, and a truncated stream is a partita::Error, never a crash;
//   - check_state() is empty for a healthy state;
//   - write_output() writes the files output_files() names; every monitor is finite, documented
//     with its unit in the registry entry, and monitor_values() agrees with monitors().
// Framework-free: it returns the failures as sentences (empty: the solver conforms), so a
// Catch2, GoogleTest or plain main() test can assert on it.
//
//   const auto failures = partita::check_solver_contract(entry, "solver: my-solver\nk: 2\n",
//                                                        "/tmp/work");
//   for (const auto& f : failures) std::cerr << f << "\n";

#include <filesystem>
#include <string>
#include <vector>

#include "partita/interface/registry.hpp"
#include "partita/interface/solver.hpp"

namespace partita {

/// `sample_yaml`: a participant section for the solver (its `solver:` key included);
/// `case_dir`: where relative inputs of the sample are found; `work_dir`: a scratch folder for
/// the output files (created; left in place). Throws only what building the solver throws.
std::vector<std::string> check_solver_contract(const Registry<SolverFactory>::Entry& entry,
                                               const std::string& sample_yaml,
                                               const std::filesystem::path& case_dir,
                                               const std::filesystem::path& work_dir);

}  // namespace partita
