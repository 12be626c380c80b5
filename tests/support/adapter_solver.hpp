#pragma once
// A registered solver built from a YAML text as a case's participant "p" would be (for the adapter
// tests): the solver's spec validates the text, relative paths resolve against `case_dir`.
#include <filesystem>
#include <memory>
#include <string>

#include <catch2/catch.hpp>

#include "partita/adapters/register_all.hpp"
#include "partita/coupling/registries.hpp"

namespace partita::test {

inline std::unique_ptr<Solver> make_solver(const std::string& solver, const std::string& yaml,
                                           const std::filesystem::path& case_dir,
                                           const std::filesystem::path& output_dir) {
  coupling::Registries r;
  coupling::register_builtin(r);
  adapters::register_all(r);
  const auto& e = r.solvers.get(solver);
  config::Node n = config::Node::load_string(yaml, solver + ".yaml");
  auto spec = std::make_shared<config::Spec>(*e.spec);
  if (!spec->find("solver")) spec->string("solver", "name").required();
  SolverContext ctx{"p", n.validated(spec), case_dir, output_dir, 1};
  return e.factory(ctx);
}

/// The value of a monitor quantity; fails the test when the solver has none of that name.
inline double monitor_value(const Solver& s, const std::string& name) {
  for (const auto& m : s.monitors())
    if (m.name == name) return m.value;
  FAIL("no monitor " << name);
  return 0.0;
}

/// The interface mesh of that name; fails the test when the solver has none.
inline const InterfaceMesh& find_mesh(const Solver& s, const std::string& name) {
  for (const auto& m : s.meshes())
    if (m.mesh.name() == name) return m;
  FAIL("no mesh " << name);
  return s.meshes().front();
}

}  // namespace partita::test
