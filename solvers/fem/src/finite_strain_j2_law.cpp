#include "partita/fem/finite_strain_j2_law.hpp"

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>

#include "partita/fem/error.hpp"
#include "symmetric_storage.hpp"

namespace partita::fem {

FiniteStrainJ2Law::FiniteStrainJ2Law(double e, double nu, double rho, HardeningCurve hardening)
    : density_(rho), hardening_(std::move(hardening)) {
  validate_isotropic_constants("j2-plasticity-finite-strain", e, nu, rho);
  const auto lame = lame_constants(e, nu);
  shear_ = lame.mu;
  bulk_ = lame.lambda + 2.0 / 3.0 * lame.mu;
}

double FiniteStrainJ2Law::dilatational_wave_speed() const {
  return std::sqrt((bulk_ + 4.0 / 3.0 * shear_) / density_);
}

void FiniteStrainJ2Law::initialise_state(std::span<double> state) const {
  std::fill(state.begin(), state.end(), 0.0);
  pack_symmetric(Mat3::Identity(), state.subspan(0, 6));  // C_p^-1 = I at rest
}

void FiniteStrainJ2Law::stress(const Mat3& f, std::span<const double> committed,
                               std::span<double> trial, Mat3& p, double& energy) const {
  const double j = f.determinant();
  require_positive_jacobian("j2-plasticity-finite-strain", j);
  const double g = shear_, k = bulk_;
  const double alpha_n = committed[6];
  // b_e_tr = F C_p_n^-1 F^T = sum lambda_a^2 n_a n_a
  const Mat3 be_tr = f * unpack_symmetric(committed.subspan(0, 6)) * f.transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(be_tr);
  const Vec3 eps_tr = 0.5 * eig.eigenvalues().array().log().matrix();  // ln lambda_a
  const Mat3& dirs = eig.eigenvectors();
  // small-strain radial return on the principal log strains
  const double tr = eps_tr.sum();
  const Vec3 e_dev = eps_tr - Vec3::Constant(tr / 3.0);
  const Vec3 s_tr = 2.0 * g * e_dev;
  const double s_norm = s_tr.norm();
  double dg = 0.0;
  Vec3 n = Vec3::Zero();
  if (s_norm - std::sqrt(2.0 / 3.0) * hardening_.yield_stress(alpha_n) > 0.0) {
    n = s_tr / s_norm;
    dg = hardening_.return_map_increment(g, s_norm, alpha_n);
  }
  // tau_a = K tr(eps) + s_tr,a - 2 G dg n_a;  eps_e = eps_tr - dg n
  const Vec3 tau_principal = Vec3::Constant(k * tr) + s_tr - 2.0 * g * dg * n;
  const Vec3 eps_e = eps_tr - dg * n;
  const Mat3 tau = dirs * tau_principal.asDiagonal() * dirs.transpose();
  // b_e = sum exp(2 eps_e,a) n_a n_a;  C_p^-1 = F^-1 b_e F^-T;  P = tau F^-T
  const Vec3 be_principal = (2.0 * eps_e).array().exp().matrix();
  const Mat3 be = dirs * be_principal.asDiagonal() * dirs.transpose();
  const Mat3 finv = f.inverse();
  p = tau * finv.transpose();
  const Vec3 ee_dev = eps_e - Vec3::Constant(eps_e.sum() / 3.0);
  // W = 1/2 K tr(eps_e)^2 + G |dev eps_e|^2
  energy = 0.5 * k * eps_e.sum() * eps_e.sum() + g * ee_dev.squaredNorm();
  pack_symmetric(finv * be * finv.transpose(), trial.subspan(0, 6));
  trial[6] = alpha_n + std::sqrt(2.0 / 3.0) * dg;
  // w_p += 1/2 (tau_n + tau_n+1) : d eps_p,  d eps_p = dg sum n_a N_a N_a
  const Mat3 deps_p = dirs * (dg * n).asDiagonal() * dirs.transpose();
  trial[7] =
      committed[7] +
      0.5 * ((unpack_symmetric(committed.subspan(8, 6)) + tau).array() * deps_p.array()).sum();
  pack_symmetric(tau, trial.subspan(8, 6));
}

void FiniteStrainJ2Law::evaluate(const Mat3& f, std::span<const double> committed,
                                 std::span<double> trial, MaterialResponse& r) const {
  stress(f, committed, trial, r.stress, r.energy_density);
  // A(:, 3 k + L) = (P(F + h E_kL) - P(F - h E_kL)) / 2h
  constexpr double h = 1e-7;
  std::array<double, kStateSize> scratch{};
  Mat3 pp, pm;
  double w = 0.0;
  for (int kk = 0; kk < 3; ++kk) {
    for (int l = 0; l < 3; ++l) {
      Mat3 fp = f, fm = f;
      fp(kk, l) += h;
      fm(kk, l) -= h;
      stress(fp, committed, scratch, pp, w);
      stress(fm, committed, scratch, pm, w);
      const Mat3 d = (pp - pm) / (2.0 * h);
      for (int i = 0; i < 3; ++i) {
        for (int jj = 0; jj < 3; ++jj) r.tangent(3 * i + jj, 3 * kk + l) = d(i, jj);
      }
    }
  }
}

}  // namespace partita::fem
