#pragma once
// Interface quasi-Newton with an inverse Jacobian from a least-squares model (IQN-ILS;
// Degroote, Bathe & Vierendeels 2009), with the details preCICE uses:
//
//   r_k = H(x_k) - x_k
//   V = [r_k - r_{k-1}, r_{k-1} - r_{k-2}, ...],  W = [H(x_k) - H(x_{k-1}), ...]   (newest first)
//   c = argmin |D (V c + r_k)|               (D = diag(weights): per-field scaling)
//   x_{k+1} = H(x_k) + W c
//
// The columns of the last `reused_windows` windows are kept (at most `max_columns` in all, the
// oldest dropped first). The QR decomposition of D V is kept across iterations and windows and
// *updated* (QrFactorization, Givens rotations, O(rows x columns) per change): each iteration
// inserts its new column at the front; columns beyond `max_columns` and the columns of windows
// older than `reused_windows` are deleted from the back; the filter deletes columns anywhere.
// Nearly dependent columns are removed from V, W and the factorisation (filter qr2:
// |R_ii| < limit |V_i| with V_i in the weighted norm, i.e. the part of column i orthogonal to
// the newer columns is short, Haelterman et al. 2016 / preCICE; qr1: |R_ii| < limit |R|_F).
// Each test runs on the updated R after the insertion, newest column first, so it sees exactly
// what a rebuild of the QR newest column first would. A column that is dependent to rounding on
// the ones in (or zero) is not inserted at all.
// Rebuilt (by appending the columns one by one with the same insert routine, the qr2 test
// applied on the way) only when the weights D change other than by a common factor (several
// accelerated fields whose norms change differently; a common factor s just scales R), when the
// data change size, and on the first call. When there are no columns (first iteration of the
// first window) the step is a constant relaxation with `initial_relaxation`. On a linear map of
// dimension n the iteration converges in at most n + 1 evaluations of H (it is then equivalent
// to GMRES). V, W, their factorisation, the filters and the iteration step are those of
// QuasiNewtonAcceleration (shared with IQN-IMVJ); this class adds the reuse of past windows'
// columns, the rescaling of R and the least-squares step.

#include <deque>
#include <memory>

#include <Eigen/Core>

#include "partita/coupling/acceleration/quasi_newton.hpp"
#include "partita/interface/config.hpp"

namespace partita::coupling {

class IqnIls : public QuasiNewtonAcceleration {
 public:
  struct Options {
    double initial_relaxation = 0.1;
    int max_columns = 50;
    int reused_windows = 8;
    Filter filter = Filter::qr2;
    double filter_limit = 1e-3;
  };

  explicit IqnIls(Options options);
  void window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                        const Eigen::VectorXd& weights) override;
  std::string name() const override { return "iqn-ils"; }
  void serialize(StateArchive& ar) override;

  /// Times the QR decomposition was rebuilt from V (instead of updated).
  long qr_rebuilds() const { return rebuilds_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Acceleration> create(const config::Node& node);

 private:
  void start_over(Eigen::Index rows) override;
  void match_weights(const Eigen::VectorXd& weights) override;
  void quasi_newton_step(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                         const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                         Eigen::VectorXd& next) override;
  void column_inserted() override { ++window_columns_.front(); }
  void column_erased(Eigen::Index j) override;
  void rebuild(const Eigen::VectorXd& weights);

  int reused_windows_;
  std::deque<int> window_columns_;  // columns per window, current window first
  long rebuilds_ = 0;
};

}  // namespace partita::coupling
