#pragma once
// Implicit coupling: each window is repeated from checkpoints until every convergence measure
// holds, the fixed point x = H(x) accelerated.
//
//   save checkpoints (window start)
//   for k = 1, 2, ...:
//     serial:   participants in order; all but the last send at once; the last one's outputs
//               are H(x_k), x_k being what the first participants read
//     parallel: all participants run from x_k (at the same time, each on a thread: see
//               set_concurrent()); all outputs form H(x_k)
//     measures on every measured field: previous iterate vs new values
//     all hold (or k = max_iterations, policy accept/error): send H(x_k), accept the window
//     else: x_{k+1} = acceleration(x_k, H(x_k)) on the accelerated fields (the others: their
//           new values); send; restore checkpoints
//
// The accelerated fields are scaled per field by 1/|x| of the previous window (preCICE's value
// preconditioner) for the accelerations that combine them.

#include <memory>
#include <vector>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/coupling/convergence/convergence_measure.hpp"
#include "partita/coupling/coupling_scheme.hpp"

namespace partita::coupling {

struct SchemeContext;

enum class OnMaxIterations { error, accept };

class ImplicitScheme : public CouplingScheme {
 public:
  struct Options {
    bool serial = true;
    int max_iterations = 100;
    OnMaxIterations on_max_iterations = OnMaxIterations::accept;
  };

  /// `accelerated`: the exchanges the acceleration acts on (empty: plain fixed-point iteration
  /// when `acceleration` is null; else the default set: the last participant's outputs for a
  /// serial scheme, every exchange for a parallel one).
  ImplicitScheme(std::vector<Participant*> participants, std::vector<Exchange*> exchanges,
                 Options options, std::vector<std::unique_ptr<ConvergenceMeasure>> measures,
                 std::unique_ptr<Acceleration> acceleration,
                 std::vector<Exchange*> accelerated = {});

  std::string name() const override {
    return options_.serial ? "implicit-serial" : "implicit-parallel";
  }
  bool parallel() const override { return !options_.serial; }
  std::vector<std::pair<std::string, std::string>> residual_columns() const override;
  const Acceleration* acceleration() const { return acceleration_.get(); }
  void serialize(StateArchive& ar) override;
  const std::vector<Exchange*>& accelerated() const { return accelerated_; }

  static std::unique_ptr<CouplingScheme> create_serial(const SchemeContext& context);
  static std::unique_ptr<CouplingScheme> create_parallel(const SchemeContext& context);

 protected:
  WindowReport run_window(const TimeWindow& window) override;

 private:
  void stack(const std::vector<Exchange*>& ex, bool previous, Eigen::VectorXd& out) const;
  void compute_weights();

  Options options_;
  std::vector<std::unique_ptr<ConvergenceMeasure>> measures_;
  std::vector<std::vector<Exchange*>> measured_;  // per measure: the exchanges of its data
  std::unique_ptr<Acceleration> acceleration_;
  std::vector<Exchange*> accelerated_;
  Eigen::VectorXd weights_;
};

}  // namespace partita::coupling
