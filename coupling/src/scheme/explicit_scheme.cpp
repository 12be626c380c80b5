#include "partita/coupling/explicit_scheme.hpp"

#include "partita/coupling/registries.hpp"

namespace partita::coupling {

ExplicitScheme::ExplicitScheme(std::vector<Participant*> participants,
                               std::vector<Exchange*> exchanges, bool serial)
    : CouplingScheme(std::move(participants), std::move(exchanges)), serial_(serial) {}

WindowReport ExplicitScheme::run_window(const TimeWindow& window) {
  if (serial_) {
    // d_{n+1} = S_1(t_n); then S_2 subcycles with d interpolated between d_n and d_{n+1}; ...
    for (Participant* p : participants_) {
      run_participant(*p, window);
      send_outputs(*p);
    }
  } else {
    run_all(window);
    for (Participant* p : participants_) send_outputs(*p);
  }
  return WindowReport{};
}

namespace {
void reject_implicit_keys(const SchemeContext& c, const std::string& scheme) {
  for (const char* key : {"convergence", "acceleration"})
    if (c.config.has(key))
      c.config[key].fail("scheme '" + scheme + "' runs each window once and takes no '" + key +
                         "'; remove it, or use scheme implicit-" + scheme.substr(9));
}
}  // namespace

std::unique_ptr<CouplingScheme> ExplicitScheme::create_serial(const SchemeContext& c) {
  reject_implicit_keys(c, "explicit-serial");
  return std::make_unique<ExplicitScheme>(c.participants, c.exchanges, true);
}

std::unique_ptr<CouplingScheme> ExplicitScheme::create_parallel(const SchemeContext& c) {
  reject_implicit_keys(c, "explicit-parallel");
  return std::make_unique<ExplicitScheme>(c.participants, c.exchanges, false);
}

}  // namespace partita::coupling
