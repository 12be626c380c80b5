#include "partita/fem/linear_elastic_law.hpp"

#include <cmath>

namespace partita::fem {

LinearElasticLaw::LinearElasticLaw(const Material& material) : material_(material) {
  material_.validate();
  lame_ = lame_constants(material_.youngs_modulus, material_.poisson_ratio);
  c_ = isotropic_elasticity_tensor(lame_.lambda, lame_.mu);
}

double LinearElasticLaw::dilatational_wave_speed() const {
  return std::sqrt((lame_.lambda + 2.0 * lame_.mu) / material_.density);
}

double LinearElasticLaw::bulk_modulus() const {
  return lame_.lambda + 2.0 / 3.0 * lame_.mu;
}

void LinearElasticLaw::evaluate(const Mat3& f, std::span<const double>, std::span<double>,
                                MaterialResponse& r) const {
  const Mat3 eps = 0.5 * (f + f.transpose()) - Mat3::Identity();
  // sigma = lambda tr(eps) I + 2 mu eps;  W = 1/2 sigma : eps
  r.stress = lame_.lambda * eps.trace() * Mat3::Identity() + 2.0 * lame_.mu * eps;
  r.tangent = c_;
  r.energy_density = 0.5 * (r.stress.array() * eps.array()).sum();
}

MaterialLawEntry linear_elastic_law_entry() {
  return {"linear-elastic", "small strain, the fast linear path", isotropic_parameters(),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<LinearElasticLaw>(Material{
                p.real("youngs_modulus"), p.real("poisson_ratio"), p.real("density")});
          }};
}

}  // namespace partita::fem
