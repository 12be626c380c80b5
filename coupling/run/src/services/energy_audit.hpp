#pragma once
// The energy audit of each pair of participants that read from each other: the work done on each
// through their interface (Solver::interface_work on the meshes it reads the other's data on),
// the energy the coupling created (their sum: a lossless interface creates none) against the work
// that passed. Beyond coupling.energy_tolerance for kWindows windows in a row the coupled run is
// unstable: it stops (or warns, coupling.on_energy_created: warn). It acts after coupling.csv and
// the monitors have their row of the window (a run it stops keeps them).

#include <cstdint>
#include <string>
#include <vector>

#include "partita/coupling/participant.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class EnergyAudit final : public Service {
 public:
  struct Pair {
    std::string label;  // "a-b"
    coupling::Participant* a = nullptr;
    coupling::Participant* b = nullptr;
    std::vector<std::string> a_meshes, b_meshes;
  };
  /// Work done on a and on b through their interface [J], and what it adds up to.
  struct Work {
    double on_a = 0.0, on_b = 0.0;
    double created() const { return on_a + on_b; }
  };

  EnergyAudit(std::vector<Pair> pairs, double tolerance, bool stop);

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "energy audit"; }
  void serialize(StateArchive& ar) override;
  void report(RunSummary& summary) const override;

  const std::vector<Pair>& pairs() const { return pairs_; }
  /// The work through the interface of pair i now.
  Work work(std::size_t i) const;
  /// The energy the coupling has created since t = 0, over every pair [J].
  double created() const;

 private:
  // since t = 0: the work on each side at the last accepted window and the work that passed
  // (sum over windows of |change on a| + |change on b|: the scale of the audit)
  struct Totals {
    double last_a = 0.0, last_b = 0.0, passed = 0.0;
    std::int64_t over = 0;  // windows in a row above the tolerance
  };
  std::vector<Pair> pairs_;
  std::vector<Totals> totals_;
  double tolerance_;
  bool stop_;
  std::int64_t warnings_ = 0;
};

}  // namespace partita::run
