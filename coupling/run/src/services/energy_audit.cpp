#include "energy_audit.hpp"

#include <cmath>

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;

namespace {
// The audit acts when the coupling has created more than the tolerated share of the work that
// passed for this many windows in a row: the lag of the explicit schemes makes single windows
// exceed it when a contact starts (granules landing on an FE floor, a plate reaching the
// granules: one or two windows at up to 100 % of a tiny amount of work), while an unstable
// coupling keeps creating energy window after window, its share growing towards 1 (the undamped
// rubber plate of README.md's energy audit). Stable explicit couplings stay well below the
// tolerance after their first windows.
constexpr int kWindows = 20;
}  // namespace

EnergyAudit::EnergyAudit(std::vector<Pair> pairs, double tolerance, bool stop)
    : pairs_(std::move(pairs)), totals_(pairs_.size()), tolerance_(tolerance), stop_(stop) {}

EnergyAudit::Work EnergyAudit::work(std::size_t i) const {
  const Pair& pair = pairs_[i];
  Work a;
  for (const auto& m : pair.a_meshes) a.on_a += pair.a->interface_work(m).value_or(0.0);
  for (const auto& m : pair.b_meshes) a.on_b += pair.b->interface_work(m).value_or(0.0);
  return a;
}

double EnergyAudit::created() const {
  double created = 0.0;
  for (std::size_t i = 0; i < pairs_.size(); ++i) created += work(i).created();
  return created;
}

void EnergyAudit::observe(FinishedWindow& w) {
  if (w.initial()) return;
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    const Pair& p = pairs_[i];
    Totals& t = totals_[i];
    const Work a = work(i);
    t.passed += std::abs(a.on_a - t.last_a) + std::abs(a.on_b - t.last_b);
    t.last_a = a.on_a;
    t.last_b = a.on_b;
    t.over = a.created() > tolerance_ * t.passed ? t.over + 1 : 0;
    if (t.over < kWindows) continue;
    const std::string what = fmt::format(
        "window {} (t = {:.6g} s): the coupling between '{}' and '{}' has created {:.4g} J, "
        "{:.0f} % of the {:.4g} J that passed through their interface (work on '{}' {:.4g} J, "
        "on '{}' {:.4g} J; a lossless interface creates none), more than "
        "coupling.energy_tolerance {:.3g} for {} windows in a row: the coupled run is "
        "unstable; shorten time.window, add damping to the structure (e.g. "
        "analysis.rayleigh.beta) or use an implicit scheme",
        w.window, w.time, p.a->name(), p.b->name(), a.created(), 100.0 * a.created() / t.passed,
        t.passed, p.a->name(), a.on_a, p.b->name(), a.on_b, tolerance_, kWindows);
    if (stop_) throw Error(what);
    if (warnings_++ == 0)
      log::get("coupling")->warn("{}; further windows are counted in the summary", what);
  }
}

// The pairs' count comes from the case (no count in the file).
void EnergyAudit::serialize(StateArchive& ar) {
  ar.io(warnings_);
  for (Totals& t : totals_) {
    ar.io(t.last_a);
    ar.io(t.last_b);
    ar.io(t.passed);
    ar.io(t.over);
  }
}

void EnergyAudit::report(RunSummary& summary) const {
  summary.energy_warnings = static_cast<long>(warnings_);
}

}  // namespace partita::run
