#include "partita/coupling/acceleration/constant_relaxation.hpp"

#include "partita/interface/error.hpp"

namespace partita::coupling {

ConstantRelaxation::ConstantRelaxation(double omega) : omega_(omega) {
  if (!(omega > 0.0 && omega <= 1.0))
    throw Error("constant relaxation factor must satisfy 0 < omega <= 1, found " +
                std::to_string(omega));
}

void ConstantRelaxation::accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                                    const Eigen::VectorXd& /*weights*/, Eigen::VectorXd& next) {
  // x_{k+1} = x_k + ω (H(x_k) - x_k)
  next = x + omega_ * (x_tilde - x);
}

std::shared_ptr<const config::Spec> ConstantRelaxation::spec() {
  auto s =
      std::make_shared<config::Spec>("constant", "constant under-relaxation x + omega (H(x) - x)");
  s->string("type", "the acceleration's name").required();
  s->real("relaxation", "the relaxation factor omega").range(0.0, 1.0).min(0.0, true).def(0.5);
  declare_accelerated_data(*s);
  return s;
}

std::unique_ptr<Acceleration> ConstantRelaxation::create(const config::Node& node) {
  return std::make_unique<ConstantRelaxation>(node.real("relaxation"));
}

}  // namespace partita::coupling
