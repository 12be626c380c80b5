// Finite-strain J2, the series evaluation (no eigen-decomposition) against the principal-space
// return through Eigen's eigen-solver (FiniteStrainJ2Law::spectral_stress, the implementation it
// replaced) over random deformation gradients: near the identity and large stretches with a
// plastic history, elastic and plastic, equal and nearly equal principal stretches; and both
// against the closed form of a coaxial elastic stretch.
#include <catch2/catch.hpp>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "partita/fem/finite_strain_j2_law.hpp"

using namespace partita::fem;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6, kH = 2.1e9;

struct Outcome {
  Mat3 p;
  double energy = 0.0;
  std::array<double, 14> state{};
};

Outcome series(const FiniteStrainJ2Law& law, const Mat3& f, const std::array<double, 14>& c) {
  Outcome o;
  MaterialResponse r;
  law.evaluate_stress(f, c, o.state, r);
  o.p = r.stress;
  o.energy = r.energy_density;
  return o;
}

Outcome spectral(const FiniteStrainJ2Law& law, const Mat3& f, const std::array<double, 14>& c) {
  Outcome o;
  law.spectral_stress(f, c, o.state, o.p, o.energy);
  return o;
}

Mat3 unpack(const std::array<double, 14>& s, int o) {
  Mat3 m;
  m << s[o], s[o + 3], s[o + 5], s[o + 3], s[o + 1], s[o + 4], s[o + 5], s[o + 4], s[o + 2];
  return m;
}

// Bounds: 1e-10 relative, with absolute floors for states near zero. Both evaluations carry a
// round-off of ~1e-16 in the log strains (b_e_tr is formed in double: its entries ~1 carry
// 1.1e-16 each), i.e. ~(3 K + 2 G) 1e-16 ~ 1e-4 Pa in tau whatever the strain: the stress floor
// 1e-14 E (2 mPa) is 20x that. For the energy density (|tau| |eps|) the floor is 1e-14 |tau|.
struct Worst {
  double p = 0.0, tau = 0.0, energy = 0.0, cp = 0.0, alpha = 0.0, wp = 0.0;
  void add(const Outcome& a, const Outcome& b) {
    const double floor = 1e-14 * kE;
    p = std::max(p, (a.p - b.p).norm() / (1e-10 * b.p.norm() + floor));
    const Mat3 ta = unpack(a.state, 8), tb = unpack(b.state, 8);
    tau = std::max(tau, (ta - tb).norm() / (1e-10 * tb.norm() + floor));
    energy = std::max(energy, std::abs(a.energy - b.energy) /
                                  (1e-10 * std::abs(b.energy) + 1e-14 * tb.norm()));
    const Mat3 ca = unpack(a.state, 0), cb = unpack(b.state, 0);
    cp = std::max(cp, (ca - cb).norm() / (1e-10 * cb.norm()));
    alpha = std::max(alpha, std::abs(a.state[6] - b.state[6]) / (1e-10 * b.state[6] + 1e-300));
    wp = std::max(wp, std::abs(a.state[7] - b.state[7]) /
                          (1e-10 * std::abs(b.state[7]) + 1e-14 * kSy));
  }
  bool holds() const {
    return p <= 1.0 && tau <= 1.0 && energy <= 1.0 && cp <= 1.0 && alpha <= 1.0 && wp <= 1.0;
  }
};

Mat3 random_matrix(std::mt19937_64& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = amplitude * u(rng);
  return m;
}

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> a(0.0, 3.14159);
  return Eigen::AngleAxisd(a(rng), Vec3(n(rng), n(rng), n(rng)).normalized()).toRotationMatrix();
}

std::array<double, 14> at_rest(const FiniteStrainJ2Law& law) {
  std::array<double, 14> s{};
  law.initialise_state(s);
  return s;
}

// A plastic history at a large F_n: reached from rest in `increments` steps of the spectral
// return along F(t) = I + t (F_n - I), each committed.
std::array<double, 14> history_at(const FiniteStrainJ2Law& law, const Mat3& f_n, int increments) {
  std::array<double, 14> c = at_rest(law);
  for (int k = 1; k <= increments; ++k) {
    const Mat3 f = Mat3::Identity() + (static_cast<double>(k) / increments) * (f_n - Mat3::Identity());
    c = spectral(law, f, c).state;
  }
  return c;
}

// spectral radius of the traceless part of b_e_tr / (tr b_e_tr / 3)
double trial_radius(const Mat3& f, const std::array<double, 14>& c) {
  const Mat3 b = f * unpack(c, 0) * f.transpose();
  const double m = b.trace() / 3.0;
  const Mat3 y = (b - m * Mat3::Identity()) / m;
  return std::sqrt(2.0 / 3.0) * y.norm();
}

}  // namespace

TEST_CASE("finite-strain j2 series path: agrees with the eigen-decomposition over random F",
          "[fem][j2][finite-strain]") {
  const FiniteStrainJ2Law law(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
  std::mt19937_64 rng(2029);
  Worst worst;
  int elastic = 0, plastic = 0, beyond = 0;
  auto check = [&](const Mat3& f, const std::array<double, 14>& c) {
    const Outcome a = series(law, f, c), b = spectral(law, f, c);
    worst.add(a, b);
    (b.state[6] > c[6] ? plastic : elastic) += 1;
    if (trial_radius(f, c) > FiniteStrainJ2Law::kSeriesRadius) ++beyond;
  };
  const auto rest = at_rest(law);
  // near the identity, from rest: 1e-8 to 1e-2 (elastic below ~1e-3, plastic above)
  for (double amp : {1e-8, 1e-6, 1e-4, 1e-3, 3e-3, 1e-2}) {
    for (int k = 0; k < 40; ++k) check(Mat3::Identity() + random_matrix(rng, amp), rest);
  }
  // large stretches (up to 1.6 and shears of 0.4) with the plastic history that reached them,
  // then a random increment of 1e-6 to 1e-2, each of these superposed with a rotation
  int histories = 0;
  for (int k = 0; k < 16; ++k) {
    const Mat3 u = Mat3::Identity() + random_matrix(rng, 0.4);
    bool invertible = true;  // along the path I + t (U - I) of history_at
    for (int m = 1; m <= 60; ++m)
      invertible = invertible && (Mat3::Identity() + m / 60.0 * (u - Mat3::Identity())).determinant() > 0.3;
    if (!invertible) continue;
    ++histories;
    const auto c = history_at(law, u, 60);
    const Mat3 f_n = random_rotation(rng) * u;
    for (double amp : {1e-6, 1e-4, 1e-3, 1e-2}) {
      for (int m = 0; m < 5; ++m) check((Mat3::Identity() + random_matrix(rng, amp)) * f_n, c);
      check(random_rotation(rng) * f_n, c);
    }
  }
  // equal and nearly equal principal stretches, elastic (1e-4) and plastic (1e-2), from rest
  // and after a plastic history
  const auto hist = history_at(law, Vec3(1.3, 0.9, 0.85).asDiagonal().toDenseMatrix(), 40);
  for (double split : {0.0, 1e-14, 1e-10, 1e-7}) {
    for (double strain : {1e-4, 1e-2}) {
      for (int k = 0; k < 8; ++k) {
        const Mat3 r = random_rotation(rng);
        const double l = 1.0 + strain, m = 1.0 - 0.7 * strain;
        const Mat3 f2 = r * Vec3(l, l * (1.0 + split), m).asDiagonal() * r.transpose();
        const Mat3 f3 = r * Vec3(l, l * (1.0 + split), l * (1.0 - split)).asDiagonal() * r.transpose();
        check(f2, rest);
        check(f3, rest);
        check(f2 * Vec3(1.3, 0.9, 0.85).asDiagonal().toDenseMatrix(), hist);
      }
    }
  }
  // beyond the series' bound: a large elastic stretch of a law with a high yield stress
  const FiniteStrainJ2Law soft(kE, kNu, kRho, HardeningCurve::linear(1e3 * kSy, kH));
  for (int k = 0; k < 10; ++k) {
    const Mat3 f = random_rotation(rng) * Vec3(1.5, 0.9, 1.1).asDiagonal() * random_rotation(rng);
    const Outcome a = series(soft, f, at_rest(soft)), b = spectral(soft, f, at_rest(soft));
    worst.add(a, b);
    if (trial_radius(f, at_rest(soft)) > FiniteStrainJ2Law::kSeriesRadius) ++beyond;
  }
  INFO(histories << " large-stretch histories; elastic " << elastic << ", plastic " << plastic << ", beyond the series bound " << beyond
                  << "; worst over the bounds (<= 1 holds): P " << worst.p << ", tau " << worst.tau
                  << ", W " << worst.energy << ", C_p^-1 " << worst.cp << ", alpha "
                  << worst.alpha << ", w_p " << worst.wp);
  CHECK(histories >= 6);
  CHECK(elastic >= 100);
  CHECK(plastic >= 100);
  CHECK(beyond >= 10);
  CHECK(worst.holds());
}

TEST_CASE("finite-strain j2 series path: a coaxial elastic stretch gives tau = K tr(ln V) I + "
          "2 G dev(ln V)",
          "[fem][j2][finite-strain]") {
  const FiniteStrainJ2Law law(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
  const double g = kE / (2.0 * (1.0 + kNu)), k = kE / (3.0 * (1.0 - 2.0 * kNu));
  std::mt19937_64 rng(7);
  double worst_series = 0.0, worst_spectral = 0.0;
  for (const Vec3& stretch : {Vec3(1.0005, 1.0005, 1.0005), Vec3(1.0004, 1.0004, 0.9999),
                             Vec3(1.0004, 1.0004 * (1.0 + 1e-12), 0.9999),
                             Vec3(0.9995, 1.0002, 1.0001), Vec3(1.0 + 1e-9, 1.0, 1.0)}) {
    const Mat3 r = random_rotation(rng);
    const Mat3 f = r * stretch.asDiagonal() * r.transpose();
    const Vec3 e = stretch.array().log().matrix();
    const Vec3 tau_a = Vec3::Constant(k * e.sum()) + 2.0 * g * (e - Vec3::Constant(e.sum() / 3.0));
    const Mat3 tau = r * tau_a.asDiagonal() * r.transpose();
    const Mat3 p = tau * f.inverse().transpose();
    const auto rest = at_rest(law);
    const double scale = 1e-12 * p.norm() + 1e-14 * kE;
    worst_series = std::max(worst_series, (series(law, f, rest).p - p).norm() / scale);
    worst_spectral = std::max(worst_spectral, (spectral(law, f, rest).p - p).norm() / scale);
  }
  INFO("worst |P - P_exact| / (1e-12 |P| + 1e-14 E): series " << worst_series << ", spectral "
                                                             << worst_spectral);
  CHECK(worst_series <= 1.0);
  CHECK(worst_spectral <= 1.0);
}
