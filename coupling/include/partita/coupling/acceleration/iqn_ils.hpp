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
// oldest dropped first). Before each solve the QR decomposition of D V is rebuilt column by
// column, newest first, and nearly dependent columns are removed from V and W
// (filter qr2: |orthogonal part| < limit |column|, Haelterman et al. 2016; qr1: |R_ii| < limit
// |R|_F). When there are no columns (first iteration of the first window) the step is a constant
// relaxation with `initial_relaxation`. On a linear map of dimension n the iteration converges
// in at most n + 1 evaluations of H (it is then equivalent to GMRES).

#include <deque>
#include <memory>

#include <Eigen/Core>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/coupling/acceleration/qr_factorization.hpp"
#include "partita/interface/config.hpp"

namespace partita::coupling {

class IqnIls : public Acceleration {
 public:
  enum class Filter { none, qr1, qr2 };
  struct Options {
    double initial_relaxation = 0.1;
    int max_columns = 50;
    int reused_windows = 8;
    Filter filter = Filter::qr2;
    double filter_limit = 1e-3;
  };

  explicit IqnIls(Options options);
  void accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                  const Eigen::VectorXd& weights, Eigen::VectorXd& next) override;
  void window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                        const Eigen::VectorXd& weights) override;
  std::string name() const override { return "iqn-ils"; }

  /// Columns in V and W now.
  Eigen::Index columns() const { return v_.cols(); }
  /// Columns removed by the filter so far.
  long filtered_columns() const { return filtered_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Acceleration> create(const config::Node& node);

 private:
  void add_columns(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde);
  void remove_column(Eigen::Index j);
  void apply_filter(const Eigen::VectorXd& weights);

  Options options_;
  Eigen::MatrixXd v_, w_;           // columns newest first
  std::deque<int> window_columns_;  // columns per window, current window first
  Eigen::VectorXd previous_residual_, previous_x_tilde_;
  bool first_iteration_ = true;
  QrFactorization qr_;
  long filtered_ = 0;
};

}  // namespace partita::coupling
