#pragma once
// The energy balance of the whole coupled system (the case's `energy:` section): named monitor
// quantities of the participants by role, summed at every window and written to DIR/energy.csv.
// The core knows nothing of what the quantities are: a case names them.
//
//   inputs      work put into the system (an indenter's, an applied load's, gravity's work)
//   stored      energy held (kinetic, elastic, potential)
//   dissipated  energy lost (plastic work, friction, damping, breakage, contact)
//
//   error = (stored + dissipated - inputs - initial) / scale,
//   initial = stored + dissipated - inputs at t = 0,
//   scale = max(sum |inputs|, sum |stored| + sum |dissipated|, floor)   (0 / 0 = 0).
//
// A window whose energy stays below the floor (both sums of magnitudes under it: the system at
// rest, a first touch's few mJ) is written to energy.csv with its error over the floor, but it
// is not held to the tolerance nor counted in the run's largest error (counts()).
//
// The coupling's own term is the net energy the interfaces created (the energy audit's sum of
// the work done on both sides of each pair, Solver::interface_work): a lossless coupling
// creates none. By default it is reported (column `coupling created [J]`) and not counted, so
// that what the coupling creates or destroys shows in the error; `coupling: counted` makes it
// an input (the error then measures the participants' own balances only).

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace partita::coupling {

class EnergyBalance {
 public:
  enum class Role { input, stored, dissipated };
  struct Term {
    Role role = Role::stored;
    std::string participant, quantity, unit;
  };
  struct Settings {
    double tolerance = 0.0;       ///< |error| above it warns once (or stops); 0: no bound
    bool stop = false;            ///< beyond the tolerance: stop the run
    double floor = 0.0;           ///< smallest scale [J]; a window below it is not counted
    bool coupling_column = false; ///< the case has interface pairs (a `coupling created` column)
    bool count_coupling = false;  ///< the coupling's created energy is an input term
  };
  struct Row {
    double inputs = 0.0, stored_dissipated = 0.0, scale = 0.0, error = 0.0;
    double measured = 0.0;  ///< max(sum |inputs|, sum |stored| + sum |dissipated|): the floor aside
  };

  EnergyBalance() = default;
  EnergyBalance(std::vector<Term> terms, Settings settings);

  const std::vector<Term>& terms() const { return terms_; }
  const Settings& settings() const { return settings_; }
  /// The CSV columns after time: each term, the coupling's, initial, the sums and the error.
  std::vector<std::pair<std::string, std::string>> columns() const;
  /// One window's row: `values` in the order of terms(), `coupling_created` the interfaces'
  /// net created energy [J]. The first call (t = 0, or the first window after a resume with no
  /// initial value) fixes the initial energy. `row` receives the CSV values after time.
  Row evaluate(const std::vector<double>& values, double coupling_created,
               std::vector<double>& row);
  /// The window's energy reached the floor: its error counts (the tolerance, the run's largest
  /// error). Without a floor every window counts.
  bool counts(const Row& r) const { return !(r.measured < settings_.floor); }
  /// A counted window's |error| beyond the tolerance (a bound was given).
  bool exceeded(const Row& r) const {
    return settings_.tolerance > 0.0 && counts(r) && !(abs_value(r.error) <= settings_.tolerance);
  }
  /// "stored 1.2 J + dissipated ... " for a diagnosis.
  std::string describe(const Row& r) const;

  // The state a restart file keeps.
  bool started() const { return started_; }
  double initial() const { return initial_; }
  void restore(bool started, double initial) {
    started_ = started;
    initial_ = initial;
  }

 private:
  static double abs_value(double v) { return v < 0.0 ? -v : v; }
  std::vector<Term> terms_;
  Settings settings_;
  bool started_ = false;
  double initial_ = 0.0;
};

const char* role_name(EnergyBalance::Role r);

}  // namespace partita::coupling
