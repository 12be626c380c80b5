#pragma once
// Aitken's dynamic relaxation (Küttler & Wall 2008), as preCICE applies it:
//   first iteration of a window: ω_1 = sign(ω) min(ω_0, |ω|)   (ω carried over from the last
//   window) later iterations:            ω_k = -ω_{k-1} r_{k-1}·(r_k - r_{k-1}) / |r_k - r_{k-1}|^2
//   x_{k+1} = x_k + ω_k r_k,     r_k = H(x_k) - x_k   (dot products in the weighted scaling)
// On a scalar linear map it gives the secant step: exact from the third iterate on.

#include <memory>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/interface/config.hpp"

namespace partita::coupling {

class Aitken : public Acceleration {
 public:
  explicit Aitken(double initial_omega);
  void accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                  const Eigen::VectorXd& weights, Eigen::VectorXd& next) override;
  void window_converged(const Eigen::VectorXd&, const Eigen::VectorXd&,
                        const Eigen::VectorXd&) override;
  std::string name() const override { return "aitken"; }
  void serialize(StateArchive& ar) override;
  /// The relaxation factor of the last accelerate().
  double omega() const { return omega_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Acceleration> create(const config::Node& node);

 private:
  double initial_omega_;
  double omega_;
  bool first_iteration_ = true;
  Eigen::VectorXd previous_residual_;
};

}  // namespace partita::coupling
