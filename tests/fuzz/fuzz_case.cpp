// libFuzzer harness: case validation without running. The input is a case file: it is loaded,
// validated against the case schema, then each participant against its registered solver's spec,
// each exchange's mapper, the acceleration and the convergence measures against theirs, as
// CaseRun does before it builds anything. No solver is built (that reads files and allocates in
// proportion to the case, which is not what this harness is about). Any input ends in a valid
// case or in partita::Error; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "partita/adapters/register_all.hpp"
#include "partita/run/case_run.hpp"
#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace {

using partita::config::Node;
using partita::coupling::Registries;

const Registries& registries() {
  static const Registries r = [] {
    Registries x;
    partita::coupling::register_builtin(x);
    partita::adapters::register_all(x);
    return x;
  }();
  return r;
}

// A registry entry's spec applied to a node that is a name or a map with 'type' (mappers,
// accelerations), as the factories do.
template <class Registry>
void validate_named(const Registry& registry, const Node& n) {
  if (!n.defined()) return;
  if (n.is_scalar()) {
    registry.get(n);
    return;
  }
  if (!n.is_map() || !n.has("type")) n.fail("expected a name or a map with 'type'");
  const auto& entry = registry.get(n["type"]);
  if (entry.spec) n.validated(entry.spec);
}

void validate_case(const std::string& text) {
  const Registries& reg = registries();
  static const auto spec = partita::run::case_spec(reg);
  const Node root = Node::load_string(text, "fuzz.yaml").validated(spec);
  (void)root["time"].real_opt("end");
  (void)root["time"].real("window");
  const Node ps = root["participants"];
  for (const std::string& name : ps.keys()) {
    const Node pn = ps[name];
    if (!pn.is_map() || !pn.has("solver")) continue;
    const auto& entry = reg.solvers.get(pn["solver"]);
    if (!entry.spec) continue;
    auto s = std::make_shared<partita::config::Spec>(*entry.spec);
    if (!s->find("solver")) s->string("solver", "the registered solver's name").required();
    pn.validated(s);
  }
  const Node coupling = root["coupling"];
  reg.schemes.get(coupling["scheme"]);
  for (const Node& item : coupling["exchanges"].items()) {
    const Node m = item["mapper"];
    partita::coupling::mapper_type(m);
    const auto& entry = reg.mappers.get(m.is_scalar() ? m : m["type"]);
    if (entry.spec) partita::coupling::mapper_options(m, entry.spec);
  }
  validate_named(reg.accelerations, coupling["acceleration"]);
  for (const Node& item : coupling["convergence"].items())
    validate_named(reg.convergence_measures, item);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  partita::log::set_level(spdlog::level::off);
  registries();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    validate_case(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const partita::Error&) {
  }
  return 0;
}
