#pragma once
// Interface quasi-Newton with an inverse Jacobian from a multi-vector update (IQN-IMVJ;
// Lindner, Mehl, Scheufele & Uekermann 2015, after Bogaers et al. 2014), with the restart
// modes of Scheufele & Mehl 2017:
//
//   r_k = H(x_k) - x_k
//   V = [r_k - r_{k-1}, ...], W = [H(x_k) - H(x_{k-1}), ...]    (this window only, newest first)
//   J_k = J_prev + (W - J_prev V) Z,  Z = (V^T D^2 V)^{-1} V^T D^2   (D = diag(weights))
//   x_{k+1} = H(x_k) - J_k r_k
//
// J_k is the inverse Jacobian (residual changes -> changes of H) nearest to J_prev, in the
// weighted norm, that satisfies the secant equations J V = W of this window. The converged
// window's J becomes J_prev of the next: the information of past windows lives in J_prev and
// is not re-fitted as IQN-ILS's reused columns are. With J_prev = 0 the step is IQN-ILS's.
// Evaluated as x_{k+1} = H(x_k) + W c - J_prev (r_k + V c), c = argmin |D (V c + r_k)|, from the
// updated QR of D V (the QR2 filter of IQN-ILS drops nearly dependent columns). V, W, their
// factorisation, the filter and the iteration step are QuasiNewtonAcceleration's (shared with
// IQN-ILS); this class adds J_prev, its update when a window converges, and the restarts.
//
// J_prev is never formed: J_prev = A B^T with A, B of rows x p; each window appends its m
// columns (A <- [A, W - J_prev V], B <- [B, D Q R^{-T}] with D V = Q R), so p grows with the
// windows. Every `chunk_size` windows a restart bounds it:
//   svd  - J_prev is replaced by its truncated SVD: singular values below `truncation` times the
//          largest are dropped (RS-SVD; the Jacobian is kept, its rank bounded);
//   zero - J_prev = 0 (RS-0: the next window starts as IQN-ILS without reuse).
// Memory: 2 x rows x p doubles; work per iteration O(rows (m + p)).
//
// Secants enter J for good, so a nearly dependent one does lasting harm: the QR2 filter limit
// defaults to 1e-2 (IQN-ILS: 1e-3). On the 1D elastic tube 1e-3 lets an ill-conditioned window
// spoil J and the run fails at window 11; 1e-2 runs at 8.1-8.4 iterations per window for chunk
// sizes 2 to 1000. Off the span of J (and of this window's secants) a step is the plain
// fixed-point update H(x); after a zero restart J has the rank of one window only, and on the
// tube the first step of the following window fails that way: prefer svd there.

#include <memory>

#include <Eigen/Core>

#include "partita/coupling/acceleration/quasi_newton.hpp"
#include "partita/interface/config.hpp"

namespace partita::coupling {

class IqnImvj : public QuasiNewtonAcceleration {
 public:
  enum class Restart { svd, zero };
  struct Options {
    double initial_relaxation = 0.1;
    int max_columns = 50;  ///< per window
    Filter filter = Filter::qr2;  ///< a case offers none and qr2
    double filter_limit = 1e-2;
    Restart restart = Restart::svd;
    int chunk_size = 8;        ///< windows between restarts
    double truncation = 1e-4;  ///< svd restart: relative singular value kept
  };

  explicit IqnImvj(Options options);
  void window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                        const Eigen::VectorXd& weights) override;
  std::string name() const override { return "iqn-imvj"; }
  void serialize(StateArchive& ar) override;

  /// The rank p of the stored J_prev = A B^T (columns of A and B).
  Eigen::Index jacobian_terms() const { return a_.cols(); }
  /// J_prev applied to y (for tests).
  Eigen::VectorXd apply_previous_jacobian(const Eigen::VectorXd& y) const;
  long restarts() const { return restarts_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Acceleration> create(const config::Node& node);

 private:
  void start_over(Eigen::Index rows) override;
  void match_weights(const Eigen::VectorXd& weights) override;
  bool has_model() const override { return v_.cols() > 0 || a_.cols() > 0; }
  void quasi_newton_step(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                         const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                         Eigen::VectorXd& next) override;
  void restart();

  Restart restart_;
  int chunk_size_;
  double truncation_;
  Eigen::MatrixXd a_, b_;  // J_prev = A B^T
  int windows_since_restart_ = 0;
  long restarts_ = 0;
};

}  // namespace partita::coupling
