#pragma once
// Explicit (staggered) coupling: every participant runs each window once. First order in the
// window size.
//   serial:   participants in order; each sends its outputs at once, so a later participant
//             sees this window's new values (Algorithm 1 of seed 000: d_{n+1} = S(t_n), then the
//             second subcycles with d interpolated between d_n and d_{n+1});
//   parallel: every participant runs from the values of the previous window, then all send
//             (those in this process at the same time, each on a thread: set_concurrent()).

#include <memory>

#include "partita/coupling/coupling_scheme.hpp"

namespace partita::coupling {

struct SchemeContext;

class ExplicitScheme : public CouplingScheme {
 public:
  ExplicitScheme(std::vector<Participant*> participants, std::vector<Exchange*> exchanges,
                 bool serial);
  std::string name() const override { return serial_ ? "explicit-serial" : "explicit-parallel"; }
  bool parallel() const override { return !serial_; }

  static std::unique_ptr<CouplingScheme> create_serial(const SchemeContext& context);
  static std::unique_ptr<CouplingScheme> create_parallel(const SchemeContext& context);

 protected:
  WindowReport run_window(const TimeWindow& window) override;

 private:
  bool serial_;
};

}  // namespace partita::coupling
