#pragma once
// Shared by the DEM adapter tests: a DEM participant built from YAML text as the core builds it,
// and its monitor values by name.
#include <catch2/catch.hpp>

#include <filesystem>
#include <memory>
#include <string>

#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"

namespace partita::test {

inline std::unique_ptr<Solver> make_dem(const std::string& yaml, const std::filesystem::path& out,
                                        const std::filesystem::path& case_dir =
                                            std::filesystem::path(PARTITA_SOURCE_DIR)) {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  const auto& e = r.solvers.get("dem");
  config::Node n = config::Node::load_string(yaml, "dem.yaml");
  auto spec = std::make_shared<config::Spec>(*e.spec);
  if (!spec->find("solver")) spec->string("solver", "name").required();
  SolverContext ctx{"p", n.validated(spec), case_dir, out, 1};
  return e.factory(ctx);
}

inline double monitor(const Solver& s, const std::string& name) {
  for (const auto& m : s.monitors())
    if (m.name == name) return m.value;
  FAIL("no monitor " << name);
  return 0.0;
}

}  // namespace partita::test
