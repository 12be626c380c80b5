#pragma once
// An acceleration of the fixed-point iteration of an implicit coupling scheme.
//
// The coupling iteration of one window is x_{k+1} = A(x_k, H(x_k)), where x is the stacked
// coupling data a participant reads and H(x) the data the other participants return for it.
// Call order (the implicit scheme guarantees it):
//   for every window:
//     for every iteration k = 1, 2, ... that did not converge:
//       accelerate(x_k, H(x_k), weights, x_{k+1})
//     window_converged(x_K, H(x_K))       — once, when the window is accepted
// `weights` scales the entries (per-field 1/norm of the previous window, as preCICE's value
// preconditioner does); an acceleration that mixes fields measures residuals in that scaling.

#include <memory>
#include <string>

#include <Eigen/Core>

namespace partita::config {
class Spec;
}
namespace partita {
class StateArchive;
}  // namespace partita

namespace partita::coupling {

/// Declares the key every acceleration takes: `data`, the fields it accelerates.
void declare_accelerated_data(config::Spec& spec);

class Acceleration {
 public:
  virtual ~Acceleration() = default;
  /// The next iterate from the current input x and the returned values x_tilde = H(x).
  virtual void accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                          const Eigen::VectorXd& weights, Eigen::VectorXd& next) = 0;
  /// The window converged with input x and returned values x_tilde; the next call starts a window.
  virtual void window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                                const Eigen::VectorXd& weights) = 0;
  /// Registered name, for messages and the summary.
  virtual std::string name() const = 0;
  /// Restart files, written and read by this one function: everything carried from window to
  /// window (between windows only), so that a resumed run iterates bit for bit as one that
  /// never stopped. Stateless: nothing.
  virtual void serialize(StateArchive& /*ar*/) {}
};

}  // namespace partita::coupling
