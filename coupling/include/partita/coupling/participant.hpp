#pragma once
// A coupling participant: a named Solver with its substep setting and the wall time it used.
// The calls to the solver go through this class, which times them (for the run's summary); a
// caller that makes several calls in a row (a substep's read, advance, write) may instead time
// them as one with a Stopwatch on solver() and add_seconds().

#include <memory>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "partita/interface/solver.hpp"

namespace partita::coupling {

/// How a participant tiles a window: a fixed number of substeps, or `auto` (the fewest
/// substeps no longer than its stable_time_step()).
struct Substeps {
  bool automatic = false;
  int count = 1;
};

class Participant {
 public:
  Participant(std::string name, std::unique_ptr<Solver> solver, Substeps substeps = {});

  const std::string& name() const { return name_; }
  Solver& solver() { return *solver_; }
  const Solver& solver() const { return *solver_; }
  const Substeps& substep_setting() const { return substeps_; }
  void set_substeps(Substeps s) { substeps_ = s; }

  /// The interface mesh of that name, or nullptr.
  const InterfaceMesh* find_mesh(std::string_view mesh) const;
  /// Substeps for a window of `window_size`: the fixed count, or ceil(size / stable_time_step()).
  int substeps(double window_size) const;

  // Timed forwards to the solver.
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values);
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values);
  void advance(double dt);
  void save_checkpoint();
  void restore_checkpoint();

  /// Wall time spent inside the solver's calls [s].
  double seconds() const { return seconds_; }
  void add_seconds(double s) { seconds_ += s; }

 private:
  std::string name_;
  std::unique_ptr<Solver> solver_;
  Substeps substeps_;
  double seconds_ = 0.0;
};

}  // namespace partita::coupling
