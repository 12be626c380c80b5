#include "partita/fem/material_contribution.hpp"

#include <array>
#include <cmath>

#include "material_contribution_kernels.hpp"

namespace partita::fem {

using detail::add_material_stiffness;
using detail::cauchy_stress_of;
using detail::evaluate_point;
using detail::stress_round_off;

// F-bar Hex8 (Hex8Formulation::FBar): at each point F_bar = (J_bar / J)^(1/3) F, J = det F,
// J_bar = (1/V) int J dV the element's volume ratio (de Souza Neto, Peric, Dutko & Owen 1996,
// Int. J. Solids Struct. 33, 3277-3296, use det F at the centre; the volume ratio makes a
// homogeneous deformation exact on distorted elements too: the patch test). The isochoric part
// of F_bar is that of F; its volume change is the element's mean: the volumetric energy sees
// one dilatation per element (no volumetric locking). Internal force and tangent are the first
// and second derivatives of Pi = int W(F_bar) dV (a variational form of F-bar), with
//   d F_bar = s (d F + F (x) (d ln J_bar - d ln J) / 3),  s = (J_bar / J)^(1/3):
//   f = int B_bar^T P_bar dV,  K = int B_bar^T A B_bar + s (e c^T + c e^T
//        + (F : P_bar)(e e^T + (H_bar - H) / 3)) dV,
// e = (d ln J_bar - d ln J) / 3, c = dF/du^T P_bar, H = d^2 ln J, H_bar = d^2 ln J_bar.
// For a hyperelastic law K is the Hessian of Pi: symmetric, so the LDL^T Newton solver applies
// unchanged, and the work of f_int is stored as int W(F_bar) dV (the energy balance closes).
// de Souza Neto's own form, int sigma(F_bar) : grad_x(dv) dv, has an unsymmetric tangent and no
// potential; it would need an LU factorisation and an energy monitor of its own.
void MaterialContribution::evaluate_fbar(std::size_t e, const ElementDisplacements& ue,
                                         ElementVector& fe, ElementMatrix* ke, double& energy,
                                         ElementVector& fabs) {
  using Vec24 = Eigen::Matrix<double, 24, 1>;
  using Mat24 = Eigen::Matrix<double, 24, 24>;
  constexpr int kPoints = 8;
  const MaterialLaw& law = *element_law_[e];
  const std::size_t q0 = qp_offset_[e];
  auto gradient = [&](int q) {
    return Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>>(
        gradients_.data() + gradient_offset_[q0 + static_cast<std::size_t>(q)]);
  };
  // H = d^2 ln J / du du:  H_(a i)(b k) = -d_ak d_bi  with d_ai = (F^-T grad_X N_a)_i
  auto hessian_ln_j = [](const Vec24& d, Mat24& h) {
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        h.block<3, 3>(3 * a, 3 * b) = -d.segment<3>(3 * b) * d.segment<3>(3 * a).transpose();
  };
  // Pass 1: F, J and d ln J / du at each point; J_bar = int J dV / V and its derivatives.
  std::array<Mat3, kPoints> f;
  std::array<double, kPoints> j;
  std::array<Vec24, kPoints> d;
  double volume = 0.0, jv = 0.0;
  Vec24 d_bar = Vec24::Zero();
  for (int q = 0; q < kPoints; ++q) {
    const auto g = gradient(q);
    f[q] = Mat3::Identity() + ue.transpose() * g;
    j[q] = f[q].determinant();
    require_not_inverted(e, j[q]);
    const Eigen::Matrix<double, 8, 3> dq = g * f[q].inverse();  // row a: (F^-T grad N_a)^T
    for (int a = 0; a < 8; ++a) d[q].segment<3>(3 * a) = dq.row(a).transpose();
    const double w = weight_[q0 + static_cast<std::size_t>(q)];
    volume += w;
    jv += w * j[q];
    d_bar += (w * j[q]) * d[q];
  }
  const double j_bar = jv / volume;
  d_bar /= jv;  // d ln J_bar = int J d dV / int J dV
  Mat24 h_bar, h;
  if (ke != nullptr) {
    // d^2 ln J_bar = int J (d d^T + H) dV / int J dV - d_bar d_bar^T
    h_bar = -d_bar * d_bar.transpose();
    for (int q = 0; q < kPoints; ++q) {
      hessian_ln_j(d[q], h);
      h_bar +=
          (weight_[q0 + static_cast<std::size_t>(q)] * j[q] / jv) * (h + d[q] * d[q].transpose());
    }
  }
  // Pass 2: the law at F_bar. With dF_bar/du = B_bar = s (G + f e^T) (G = dF/du, f = vec F,
  // e = (d_bar - d) / 3) and p = vec P_bar:
  //   f_e += w s (G^T p + (F : P_bar) e)
  //   K_e += w [s^2 (G^T A G + (G^T A f) e^T + e (G^T A^T f)^T + (f . A f) e e^T)
  //             + s (e c^T + c e^T + (F : P_bar)(e e^T + (H_bar - H) / 3))],  c = G^T p,
  // the rank-one terms written out so that a point costs about twice a plain one.
  MaterialResponse resp;
  Eigen::Matrix<double, 9, 1> fv, af, atf;
  Vec24 c, ga, gat;
  double h_bar_scale = 0.0;  // sum over the points of w s (F : P_bar) / 3
  for (int q = 0; q < kPoints; ++q) {
    const std::size_t qp = q0 + static_cast<std::size_t>(q);
    const auto g = gradient(q);
    const double s = std::cbrt(j_bar / j[q]);
    const Mat3 fb = s * f[q];
    const std::size_t s0 = state_offset_[qp], ns = state_offset_[qp + 1] - s0;
    evaluate_point(law, fb, std::span<const double>(committed_).subspan(s0, ns),
                   std::span<double>(trial_).subspan(s0, ns), step_, ke != nullptr, resp);
    const double w = weight_[qp];
    energy += resp.energy_density * w;
    const Mat3 sigma = cauchy_stress_of(law, resp.stress, fb);
    const auto qi = static_cast<Eigen::Index>(qp);
    cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2), sigma(0, 2);
    eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
    // c_bk = (P_bar grad N_b)_k = (G^T p)_bk;  phi = F : P_bar
    for (int b = 0; b < 8; ++b) c.segment<3>(3 * b) = resp.stress * g.row(b).transpose();
    const double phi = (f[q].array() * resp.stress.array()).sum();
    const Vec24 ev = (d_bar - d[q]) / 3.0;
    fe.head<24>() += (w * s) * (c + phi * ev);
    // round-off bound (as the plain element's, with F_bar)
    const double dp = stress_round_off(resp.stress, fb, element_modulus_[e]) * w * s;
    for (int a = 0; a < 8; ++a) fabs[a] += g.row(a).norm() * dp;
    if (ke == nullptr) continue;
    for (int i = 0; i < 3; ++i)
      for (int jj = 0; jj < 3; ++jj) fv[3 * i + jj] = f[q](i, jj);
    af = resp.tangent * fv;
    atf = resp.tangent.transpose() * fv;
    // (G^T v)_bk = sum_J v_kJ dN_b/dX_J for a 9-vector v indexed 3 k + J
    for (int b = 0; b < 8; ++b) {
      for (int kk = 0; kk < 3; ++kk) {
        ga[3 * b + kk] = g.row(b).dot(af.segment<3>(3 * kk));
        gat[3 * b + kk] = g.row(b).dot(atf.segment<3>(3 * kk));
      }
    }
    add_material_stiffness(g, resp.tangent, w * s * s, *ke);
    const Vec24 left = (s * s) * ga + s * c, right = (s * s) * gat + s * c;
    auto k24 = ke->topLeftCorner<24, 24>();
    k24.noalias() += w * (left * ev.transpose() + ev * right.transpose());
    k24.noalias() += (w * (s * s * fv.dot(af) + s * phi)) * (ev * ev.transpose());
    // - (w s phi / 3) H at this point; + (w s phi / 3) H_bar collected below
    const double hs = w * s * phi / 3.0;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        k24.block<3, 3>(3 * a, 3 * b).noalias() +=
            hs * d[q].segment<3>(3 * b) * d[q].segment<3>(3 * a).transpose();
    h_bar_scale += hs;
  }
  if (ke != nullptr) ke->topLeftCorner<24, 24>() += h_bar_scale * h_bar;
}

}  // namespace partita::fem
