#include "partita/fem/j2_plasticity_law.hpp"

#include <cmath>

#include "partita/fem/error.hpp"
#include "symmetric_storage.hpp"

namespace partita::fem {

J2PlasticityLaw::J2PlasticityLaw(double e, double nu, double rho, HardeningCurve hardening,
                                 std::optional<CowperSymonds> strain_rate)
    : elastic_{e, nu, rho},
      density_(rho),
      hardening_(std::move(hardening)),
      strain_rate_(std::move(strain_rate)) {
  validate_isotropic_constants("j2-plasticity", e, nu, rho);
  const auto lame = lame_constants(e, nu);
  shear_ = lame.mu;
  bulk_ = lame.lambda + 2.0 / 3.0 * lame.mu;
}

double J2PlasticityLaw::dilatational_wave_speed() const {
  return std::sqrt((bulk_ + 4.0 / 3.0 * shear_) / density_);
}

void J2PlasticityLaw::evaluate_with(const Mat3& f, std::span<const double> committed,
                                    std::span<double> trial, MaterialResponse& r,
                                    bool with_tangent, const MaterialStep& step) const {
  const double g = shear_, k = bulk_;
  const double sqrt23 = std::sqrt(2.0 / 3.0);
  const Mat3 id = Mat3::Identity();
  const Mat3 eps = 0.5 * (f + f.transpose()) - id;
  const Mat3 eps_p_n = unpack_symmetric(committed.subspan(0, 6));
  const double alpha_n = committed[6];
  const double wp_n = committed[7];

  const Mat3 eps_e_tr = eps - eps_p_n;
  const double tr = eps_e_tr.trace();
  // s_tr = 2 G dev(eps - eps_p_n)
  const Mat3 s_tr = 2.0 * g * (eps_e_tr - tr / 3.0 * id);
  const double s_norm = s_tr.norm();
  // f_tr = |s_tr| - sqrt(2/3) sigma_y(alpha_n)
  const double f_tr = s_norm - sqrt23 * hardening_.yield_stress(alpha_n);

  double dg = 0.0, theta = 1.0, theta_bar = 0.0;
  Mat3 n = Mat3::Zero();
  // a rate-dependent dynamic step: the viscoplastic return (none at dt = 0: no time to flow)
  const bool rate = strain_rate_ && step.dynamic;
  if (f_tr > 0.0 && rate && step.time_increment > 0.0) {
    n = s_tr / s_norm;
    // Solve |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha) [1 + (sqrt(2/3) dg / (dt D))^(1/q)] = 0
    const CowperSymonds::Return ret =
        strain_rate_->return_map(hardening_, g, s_norm, alpha_n, step.time_increment);
    dg = ret.dg;
    theta = 1.0 - 2.0 * g * dg / s_norm;
    theta_bar = 1.0 / (1.0 + ret.slope / (3.0 * g)) - (1.0 - theta);
  } else if (f_tr > 0.0 && !rate) {
    n = s_tr / s_norm;
    // Solve |s_tr| - 2 G dg - sqrt(2/3) sigma_y(alpha_n + sqrt(2/3) dg) = 0
    dg = hardening_.return_map_increment(g, s_norm, alpha_n);
    theta = 1.0 - 2.0 * g * dg / s_norm;
    theta_bar = 1.0 / (1.0 + hardening_.slope(alpha_n + sqrt23 * dg) / (3.0 * g)) - (1.0 - theta);
  }
  // sigma = K tr(eps_e) I + s_tr - 2 G dg n
  const Mat3 s = s_tr - 2.0 * g * dg * n;
  r.stress = k * tr * id + s;
  // C_ep = K 1(x)1 + 2 G theta (I_sym - 1/3 1(x)1) - 2 G theta_bar n(x)n, entry (3 i + j, 3 a + b)
  // (the constant tensors once; each entry's operations in the order of the formula)
  if (with_tangent) {
    struct Constant {
      Matrix9 one_one, deviator;  // 1(x)1 (d_ij d_ab), I_sym - 1/3 1(x)1
    };
    static const Constant c = [] {
      Constant t;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          for (int a = 0; a < 3; ++a) {
            for (int b = 0; b < 3; ++b) {
              const double dij_ab = (i == j && a == b) ? 1.0 : 0.0;
              const double isym =
                  0.5 * ((i == a && j == b ? 1.0 : 0.0) + (i == b && j == a ? 1.0 : 0.0));
              t.one_one(3 * i + j, 3 * a + b) = dij_ab;
              t.deviator(3 * i + j, 3 * a + b) = isym - dij_ab / 3.0;
            }
          }
        }
      }
      return t;
    }();
    Eigen::Matrix<double, 9, 1> nv;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) nv[3 * i + j] = n(i, j);
    const double c_dev = 2.0 * g * theta, c_nn = 2.0 * g * theta_bar;
    r.tangent = k * c.one_one + c_dev * c.deviator - (c_nn * nv) * nv.transpose();
  }
  const Mat3 eps_p = eps_p_n + dg * n;
  const Mat3 eps_e = eps - eps_p;
  // W = 1/2 (eps - eps_p) : sigma
  r.energy_density = 0.5 * (eps_e.array() * r.stress.array()).sum();
  pack_symmetric(eps_p, trial.subspan(0, 6));
  trial[6] = alpha_n + sqrt23 * dg;
  // w_p += 1/2 (sigma_n + sigma_n+1) : d eps_p,  d eps_p = dg n
  const Mat3 sigma_n = unpack_symmetric(committed.subspan(8, 6));
  trial[7] = wp_n + 0.5 * dg * ((sigma_n + r.stress).array() * n.array()).sum();
  pack_symmetric(r.stress, trial.subspan(8, 6));
}

MaterialLawEntry j2_plasticity_law_entry() {
  auto parameters = isotropic_parameters();
  for (auto& h : hardening_parameters()) parameters.push_back(std::move(h));
  for (auto& r : strain_rate_parameters()) parameters.push_back(std::move(r));
  return {"j2-plasticity", "small strain, isotropic hardening", std::move(parameters),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<J2PlasticityLaw>(
                p.real("youngs_modulus"), p.real("poisson_ratio"), p.real("density"),
                hardening_curve_from("j2-plasticity", p), strain_rate_from("j2-plasticity", p));
          },
          [](const MaterialParameters& p) {
            if (auto issue = check_hardening("j2-plasticity", p)) return issue;
            return check_strain_rate("j2-plasticity", p);
          }};
}

}  // namespace partita::fem
