#pragma once
// Constant under-relaxation: x_{k+1} = x_k + ω (H(x_k) - x_k).
// On a linear map H(x) = λ x + b the error contracts by |1 - ω (1 - λ)| per iteration.

#include <memory>

#include "partita/coupling/acceleration/acceleration.hpp"
#include "partita/interface/config.hpp"

namespace partita::coupling {

class ConstantRelaxation : public Acceleration {
 public:
  explicit ConstantRelaxation(double omega);
  void accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                  const Eigen::VectorXd& weights, Eigen::VectorXd& next) override;
  void window_converged(const Eigen::VectorXd&, const Eigen::VectorXd&,
                        const Eigen::VectorXd&) override {}
  std::string name() const override { return "constant"; }
  double omega() const { return omega_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Acceleration> create(const config::Node& node);

 private:
  double omega_;
};

}  // namespace partita::coupling
