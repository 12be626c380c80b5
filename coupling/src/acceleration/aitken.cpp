#include "partita/coupling/acceleration/aitken.hpp"

#include <cmath>

#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

Aitken::Aitken(double initial_omega) : initial_omega_(initial_omega), omega_(initial_omega) {
  if (!(initial_omega > 0.0 && initial_omega <= 1.0))
    throw Error("Aitken initial relaxation must satisfy 0 < omega <= 1, found " +
                std::to_string(initial_omega));
}

void Aitken::accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                        const Eigen::VectorXd& weights, Eigen::VectorXd& next) {
  const Eigen::VectorXd r = weights.cwiseProduct(x_tilde - x);  // scaled residual
  if (first_iteration_ || previous_residual_.size() != r.size()) {
    // ω_1 = sign(ω) min(ω_0, |ω|)
    omega_ = std::copysign(std::min(initial_omega_, std::abs(omega_)), omega_);
  } else {
    // ω_k = -ω_{k-1} r_{k-1}·(r_k - r_{k-1}) / |r_k - r_{k-1}|^2
    const Eigen::VectorXd dr = r - previous_residual_;
    const double denominator = dr.squaredNorm();
    if (denominator > 0.0) omega_ = -omega_ * previous_residual_.dot(dr) / denominator;
  }
  // x_{k+1} = x_k + ω_k r_k
  next = x + omega_ * (x_tilde - x);
  previous_residual_ = r;
  first_iteration_ = false;
}

void Aitken::window_converged(const Eigen::VectorXd&, const Eigen::VectorXd&,
                              const Eigen::VectorXd&) {
  first_iteration_ = true;
}

std::shared_ptr<const config::Spec> Aitken::spec() {
  auto s = std::make_shared<config::Spec>(
      "aitken", "Aitken's dynamic under-relaxation (Kuettler & Wall 2008)");
  s->string("type", "the acceleration's name").required();
  s->real("initial_relaxation",
          "relaxation factor of the first iteration (and upper bound of the first "
          "iteration of every window)")
      .min(0.0, true)
      .max(1.0)
      .def(0.5);
  declare_accelerated_data(*s);
  return s;
}

std::unique_ptr<Acceleration> Aitken::create(const config::Node& node) {
  return std::make_unique<Aitken>(node.real("initial_relaxation"));
}

void Aitken::serialize(StateArchive& ar) {
  ar.section("aitken");
  ar.io(omega_);
  ar.io(first_iteration_);
  ar.io(previous_residual_);
}

}  // namespace partita::coupling
