#pragma once
// What the interface quasi-Newton accelerations (IQN-ILS, IQN-IMVJ) share, in the way of
// preCICE's base quasi-Newton acceleration: the difference matrices of the window's iterations
//
//   r_k = H(x_k) - x_k
//   V = [r_k - r_{k-1}, r_{k-1} - r_{k-2}, ...],  W = [H(x_k) - H(x_{k-1}), ...]   (newest first)
//
// with the updated QR factorisation of D V (D = diag(weights), QrFactorization), the filter of
// nearly dependent columns, and the one iteration step every variant takes:
//
//   accelerate(x, H(x)):
//     the data changed size?  start over (start_over)
//     factorisation of D V for these weights (match_weights: each variant decides how)
//     insert the newest secant at the front of V, W and the QR (a zero secant, or one dependent
//       on the columns in to rounding, is not inserted); drop the oldest beyond max_columns
//     filter (qr1 or qr2, on the updated R: each test sees the columns that are still in)
//     no model yet (has_model)?  x_{k+1} = x_k + omega_0 r_k  (constant relaxation)
//     otherwise x_{k+1} from the variant's own model (quasi_newton_step)
//
// What happens when a window converges (which columns stay, what is carried into the next
// window) is each variant's own: window_converged.

#include <string>

#include <Eigen/Core>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/coupling/acceleration/qr_factorization.hpp"

namespace partita::coupling {

class QuasiNewtonAcceleration : public Acceleration {
 public:
  /// Filters of nearly dependent columns: qr1 drops column i when |R_ii| < limit |R|_F; qr2 when
  /// |R_ii| < limit |V_i| (V_i in the weighted norm: the part of column i orthogonal to the
  /// newer columns is short; Haelterman et al. 2016, preCICE).
  enum class Filter { none, qr1, qr2 };

  void accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                  const Eigen::VectorXd& weights, Eigen::VectorXd& next) final;

  /// Columns in V and W now.
  Eigen::Index columns() const { return v_.cols(); }
  /// Columns removed by the filter (or refused as dependent) so far.
  long filtered_columns() const { return filtered_; }
  /// The factorisation of D V (D: the weights it was made with).
  const QrFactorization& qr() const { return qr_; }
  /// V and W, newest column first.
  const Eigen::MatrixXd& v() const { return v_; }
  const Eigen::MatrixXd& w() const { return w_; }

 protected:
  struct Settings {
    double initial_relaxation;
    int max_columns;
    Filter filter;
    double filter_limit;
  };
  /// Throws partita::Error (the messages name `label`) unless 0 < initial_relaxation <= 1 and
  /// max_columns >= 1.
  QuasiNewtonAcceleration(const std::string& label, Settings settings);

  /// No columns, `rows` entries per column (and whatever the variant carries: its start_over).
  virtual void start_over(Eigen::Index rows);
  /// Make qr_ the factorisation of D V for these weights (called before each new secant).
  virtual void match_weights(const Eigen::VectorXd& weights) = 0;
  /// Whether there is a model to step with (else the step is a constant relaxation).
  virtual bool has_model() const { return v_.cols() > 0; }
  /// x_{k+1} from the model; r = x_tilde - x.
  virtual void quasi_newton_step(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                                 const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                                 Eigen::VectorXd& next) = 0;
  /// Bookkeeping of a variant that tracks columns (IQN-ILS: which window owns which column):
  /// a secant entered V at the front; column j left V.
  virtual void column_inserted() {}
  virtual void column_erased(Eigen::Index /*j*/) {}

  /// The size check, match_weights and the newest secant (see the file comment).
  void update_difference_matrices(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                                  const Eigen::VectorXd& weights);
  /// The filter of the settings on the current factorisation.
  void apply_filter();
  /// qr_ from scratch: D V by appending the columns newest first (no rotations); a column whose
  /// orthogonal part is below `limit` of its norm (or dependent to rounding) leaves V and W.
  void factorise(const Eigen::VectorXd& weights, double limit);
  /// Column j out of V and W (the factorisation untouched).
  void erase_column(Eigen::Index j);
  /// Column j out of V, W and the factorisation.
  void remove_column(Eigen::Index j);
  /// c = argmin |D (V c + r)| from the factorisation.
  Eigen::VectorXd least_squares(const Eigen::VectorXd& r, const Eigen::VectorXd& weights) const {
    return qr_.solve(-weights.cwiseProduct(r));
  }

  Settings settings_;
  Eigen::MatrixXd v_, w_;       // columns newest first
  QrFactorization qr_;          // of D V, D = diag(qr_weights_)
  Eigen::VectorXd qr_weights_;  // empty: no factorisation yet
  Eigen::VectorXd previous_residual_, previous_x_tilde_;
  bool first_iteration_ = true;  // of a window: no secant to take yet
  long filtered_ = 0;

 private:
  void insert_secant(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                     const Eigen::VectorXd& weights);
};

}  // namespace partita::coupling
