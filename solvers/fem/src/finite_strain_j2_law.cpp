#include "partita/fem/finite_strain_j2_law.hpp"

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>

#include "partita/fem/error.hpp"
#include "symmetric_storage.hpp"

namespace partita::fem {

namespace {

// sum_n c_n Y^n = i I + y Y + y2 Y^2 for a traceless symmetric Y, through Cayley-Hamilton
// (Y^3 = j2 Y + j3 I, j2 = 1/2 tr Y^2, j3 = det Y): the powers are carried as the three
// coefficients of I, Y and Y^2, Y^n+1 = Y Y^n. No eigenvectors, so equal and nearly equal
// eigenvalues need no special case.
struct SeriesCoefficients {
  double i = 0.0, y = 0.0, y2 = 0.0;
};

template <class Coefficient>
SeriesCoefficients traceless_series(double j2, double j3, int terms, Coefficient c) {
  SeriesCoefficients s{c(0), 0.0, 0.0};
  double p = 0.0, q = 1.0, r = 0.0;  // Y^1
  for (int n = 1; n <= terms; ++n) {
    const double cn = c(n);
    s.i += cn * p;
    s.y += cn * q;
    s.y2 += cn * r;
    const double p1 = r * j3, q1 = p + r * j2;
    r = q;
    p = p1;
    q = q1;
  }
  return s;
}

// The series bounds, on rho >= the spectral radius of Y (sqrt(2/3) |Y| for a traceless Y):
// terms N of ln(I + Y) = sum (-1)^(n+1) Y^n / n such that the tail, below
// rho^(N+1) / ((N+1) (1 - rho)), is under 2^-56 rho (the eigen-decomposition's own round-off is
// ~1e-16 of b_e); of exp(Y) = sum Y^n / n! such that rho^(N+1) / (N+1)! / (1 - rho / (N+2)) is
// under 2^-56. (The coefficients of Y^n in the basis I, Y, Y^2 grow at most as n^2 rho^n for
// repeated eigenvalues: the margin 2^-56 ~ 1.4e-17 against 1e-16 covers it at the N used.)
constexpr double kSeriesTolerance = 0x1p-56;
int log_terms(double rho) {
  int n = 1;
  double t = rho * rho;  // rho^(n+1)
  const double bound = kSeriesTolerance * rho * (1.0 - rho);
  while (t > bound * (n + 1) && n < 60) {
    ++n;
    t *= rho;
  }
  return n;
}
int exp_terms(double rho) {
  int n = 1;
  double t = rho * rho / 2.0;  // rho^(n+1) / (n+1)!
  while (t > kSeriesTolerance * (1.0 - rho / (n + 2)) && n < 60) {
    ++n;
    t *= rho / (n + 1);
  }
  return n;
}

// 1 / n!, n = 0 ... 60
constexpr std::array<double, 61> kInverseFactorial = [] {
  std::array<double, 61> v{};
  v[0] = 1.0;
  for (std::size_t n = 1; n < v.size(); ++n) v[n] = v[n - 1] / static_cast<double>(n);
  return v;
}();

// (-1)^(n+1) / n, n = 1 ... 60 (0 at n = 0): the coefficients of ln(I + Y)
constexpr std::array<double, 61> kLogCoefficient = [] {
  std::array<double, 61> v{};
  for (std::size_t n = 1; n < v.size(); ++n)
    v[n] = ((n % 2) != 0 ? 1.0 : -1.0) / static_cast<double>(n);
  return v;
}();

inline double spectral_radius_bound(double j2) {
  return std::sqrt(4.0 / 3.0 * j2);  // sqrt(2/3) |Y|, |Y|^2 = 2 j2
}

// b_e_tr = F C_p_n^-1 F^T, after the check det F > 0
Mat3 trial_elastic_left_cauchy_green(const Mat3& f, std::span<const double> committed) {
  require_positive_jacobian("j2-plasticity-finite-strain", f.determinant());
  return f * unpack_symmetric(committed.subspan(0, 6)) * f.transpose();
}

}  // namespace

FiniteStrainJ2Law::FiniteStrainJ2Law(double e, double nu, double rho, HardeningCurve hardening,
                                     std::optional<CowperSymonds> strain_rate)
    : elastic_{e, nu, rho},
      density_(rho),
      hardening_(std::move(hardening)),
      strain_rate_(std::move(strain_rate)) {
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

double FiniteStrainJ2Law::return_increment(double s_norm, double alpha_n,
                                           const MaterialStep& step) const {
  if (!(s_norm - std::sqrt(2.0 / 3.0) * hardening_.yield_stress(alpha_n) > 0.0)) return 0.0;
  if (!strain_rate_ || !step.dynamic) return hardening_.return_map_increment(shear_, s_norm, alpha_n);
  // a dynamic step at the committed instant (dt = 0) leaves no time for viscous flow
  if (!(step.time_increment > 0.0)) return 0.0;
  return strain_rate_->return_map(hardening_, shear_, s_norm, alpha_n, step.time_increment).dg;
}

void FiniteStrainJ2Law::stress(const Mat3& f, std::span<const double> committed,
                               std::span<double> trial, Mat3& p, double& energy,
                               const MaterialStep& step) const {
  const Mat3 be_tr = trial_elastic_left_cauchy_green(f, committed);
  const double g = shear_, k = bulk_;
  const double alpha_n = committed[6];
  const Mat3 id = Mat3::Identity();
  // b_e_tr = c (I + Y), c = tr(b_e_tr) / 3, Y traceless
  const double c = be_tr.trace() / 3.0;
  const Mat3 y = (be_tr - c * id) / c;
  const Mat3 y2 = y * y;
  const double j2 = 0.5 * y2.trace();
  const double rho = spectral_radius_bound(j2);
  if (!(rho <= kSeriesRadius)) {
    spectral_stress(f, committed, trial, p, energy, step);
    return;
  }
  // eps_tr = 1/2 ln b_e_tr = 1/2 (ln c I + ln(I + Y)); ln(I + Y) = l_i I + l_y Y + l_y2 Y^2
  const SeriesCoefficients l =
      traceless_series(j2, y.determinant(), log_terms(rho),
                       [](int n) { return kLogCoefficient[static_cast<std::size_t>(n)]; });
  // tr eps_tr = 1/2 (3 ln c + 3 l_i + 2 j2 l_y2); dev eps_tr = 1/2 (l_y Y + l_y2 dev Y^2)
  const double tr = 0.5 * (3.0 * std::log(c) + 3.0 * l.i + 2.0 * j2 * l.y2);
  const Mat3 y2_dev = y2 - (2.0 * j2 / 3.0) * id;
  const Mat3 e_dev = 0.5 * (l.y * y + l.y2 * y2_dev);
  // small-strain radial return on the log strains (coaxial with b_e_tr)
  const Mat3 s_tr = 2.0 * g * e_dev;
  const double s_norm = s_tr.norm();
  const double dg = return_increment(s_norm, alpha_n, step);
  // tau = K tr(eps) I + s_tr - 2 G dg n = K tr I + theta s_tr;  dev eps_e = theta dev eps_tr
  const double theta = dg > 0.0 ? 1.0 - 2.0 * g * dg / s_norm : 1.0;
  const Mat3 tau = (k * tr) * id + theta * s_tr;
  const Mat3 finv = f.inverse();
  p = tau * finv.transpose();
  // W = 1/2 K tr(eps_e)^2 + G |dev eps_e|^2
  energy = 0.5 * k * tr * tr + g * theta * theta * e_dev.squaredNorm();
  trial[6] = alpha_n + std::sqrt(2.0 / 3.0) * dg;
  if (dg > 0.0) {
    // b_e = exp(2 eps_e) = exp(2/3 tr) exp(D), D = 2 theta dev eps_tr;  C_p^-1 = F^-1 b_e F^-T
    const Mat3 d = (2.0 * theta) * e_dev;
    const Mat3 d2 = d * d;
    const double j2d = 0.5 * d2.trace();
    const SeriesCoefficients x = traceless_series(
        j2d, d.determinant(), exp_terms(spectral_radius_bound(j2d)),
        [](int n) { return kInverseFactorial[static_cast<std::size_t>(n)]; });
    const Mat3 be = std::exp(2.0 / 3.0 * tr) * (x.i * id + x.y * d + x.y2 * d2);
    pack_symmetric(finv * be * finv.transpose(), trial.subspan(0, 6));
    // w_p += 1/2 (tau_n + tau_n+1) : d eps_p,  d eps_p = dg n,  n = s_tr / |s_tr|
    trial[7] = committed[7] + 0.5 * dg / s_norm *
                                  ((unpack_symmetric(committed.subspan(8, 6)) + tau).array() *
                                   s_tr.array())
                                      .sum();
  } else {
    // elastic: b_e = b_e_tr, so C_p^-1 = F^-1 b_e_tr F^-T = C_p_n^-1
    std::copy_n(committed.begin(), 6, trial.begin());
    trial[7] = committed[7];
  }
  pack_symmetric(tau, trial.subspan(8, 6));
}

void FiniteStrainJ2Law::spectral_stress(const Mat3& f, std::span<const double> committed,
                                        std::span<double> trial, Mat3& p, double& energy,
                                        const MaterialStep& step) const {
  // b_e_tr = sum lambda_a^2 n_a n_a
  const Mat3 be_tr = trial_elastic_left_cauchy_green(f, committed);
  const double g = shear_, k = bulk_;
  const double alpha_n = committed[6];
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
    dg = return_increment(s_norm, alpha_n, step);
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
void FiniteStrainJ2Law::evaluate_step(const Mat3& f, std::span<const double> committed,
                                      std::span<double> trial, const MaterialStep& step,
                                      MaterialResponse& r) const {
  stress(f, committed, trial, r.stress, r.energy_density, step);
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
      stress(fp, committed, scratch, pp, w, step);
      stress(fm, committed, scratch, pm, w, step);
      const Mat3 d = (pp - pm) / (2.0 * h);
      for (int i = 0; i < 3; ++i) {
        for (int jj = 0; jj < 3; ++jj) r.tangent(3 * i + jj, 3 * kk + l) = d(i, jj);
      }
    }
  }
}

MaterialLawEntry finite_strain_j2_law_entry() {
  auto parameters = isotropic_parameters();
  for (auto& h : hardening_parameters()) parameters.push_back(std::move(h));
  for (auto& r : strain_rate_parameters()) parameters.push_back(std::move(r));
  return {"j2-plasticity-finite-strain", "multiplicative, logarithmic strains",
          std::move(parameters),
          [](const MaterialParameters& p) -> std::shared_ptr<const MaterialLaw> {
            return std::make_shared<FiniteStrainJ2Law>(
                p.real("youngs_modulus"), p.real("poisson_ratio"), p.real("density"),
                hardening_curve_from("j2-plasticity-finite-strain", p),
                strain_rate_from("j2-plasticity-finite-strain", p));
          },
          [](const MaterialParameters& p) {
            if (auto issue = check_hardening("j2-plasticity-finite-strain", p)) return issue;
            return check_strain_rate("j2-plasticity-finite-strain", p);
          }};
}

}  // namespace partita::fem
