#pragma once
// Shared by the DEM adapter tests: a DEM participant built from YAML text as the core builds it,
// and its monitor values by name (thin names over tests/support/adapter_solver.hpp).
#include <filesystem>
#include <memory>
#include <string>

#include "../support/adapter_solver.hpp"

namespace partita::test {

inline std::unique_ptr<Solver> make_dem(const std::string& yaml, const std::filesystem::path& out,
                                        const std::filesystem::path& case_dir =
                                            std::filesystem::path(PARTITA_SOURCE_DIR)) {
  return make_solver("dem", yaml, case_dir, out);
}

inline double monitor(const Solver& s, const std::string& name) { return monitor_value(s, name); }

}  // namespace partita::test
