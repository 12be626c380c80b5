#include "partita/fem/material_contribution.hpp"

#include <Eigen/LU>
#include <array>
#include <sstream>

#include "partita/fem/error.hpp"

#include "material_contribution_kernels.hpp"

namespace partita::fem {

using detail::add_material_stiffness;
using detail::cauchy_stress_of;
using detail::evaluate_point;
using detail::stress_round_off;

// EAS Hex8 (Hex8Formulation::IncompatibleModes, the default: the nonlinear path's form of the
// linear path's incompatible modes): enhanced assumed strain after Simo & Armero (IJNME 33,
// 1992, 1413-1449) with the 9 modes of Simo, Armero & Taylor (CMAME 110, 1993, 359-386) and
// Taylor, Beresford & Wilson's constant-Jacobian scaling (so that the patch test passes on
// distorted elements):
//   F = I + sum_a u_a (x) grad_X N_a + sum_J alpha_J (x) g_J,
//   g_J(xi) = (j0 / j(xi)) xi_J (J0^-1)_J.   (J0 = dX/dxi, j0 = det J0 at the centre; row J)
// The three g_J act as the gradients of three extra "nodes" whose 9 displacements alpha are
// element unknowns: the element is the plain one of 11 nodes, its alpha found per element
// (local Newton from the committed alpha, h(u, alpha) = int G^T P dV = 0) and condensed:
//   f_e = f_u - K_ua K_aa^-1 h,   K_e = K_uu - K_ua K_aa^-1 K_au.
// int g_J dV = 0 for any symmetric rule (the orthogonality that makes the patch test pass);
// for small strains the element is Wilson's / Taylor's QM6 (Simo & Rifai 1990). No shear
// locking in bending, no volumetric locking up to nu ~ 0.49. Rule: 2x2x2 Gauss; a thin element
// (its thinnest direction less than half as thick as both others) gets 2x2 x 6 Gauss points
// with 6 through the thickness, so that it yields from its surfaces inward (a fully plastic
// section's moment integrated to +2 %, where 2 points overestimate it by 15 %).
void MaterialContribution::evaluate_eas(std::size_t e, const ElementDisplacements& ue,
                                        ElementVector& fe, ElementMatrix* ke, double& energy,
                                        ElementVector& fabs) {
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  using Mat33 = Eigen::Matrix<double, 33, 33>;
  using Vec33 = Eigen::Matrix<double, 33, 1>;
  using Grad11 = Eigen::Matrix<double, 11, 3>;
  constexpr int kMaxLocalIterations = 12;
  const MaterialLaw& law = *element_law_[e];
  const std::size_t q0 = qp_offset_[e], q1 = qp_offset_[e + 1];
  const std::size_t a0 = eas_offset_[e];
  // 11 "nodes": the 8 nodes, then the three enhanced modes (displacements alpha_J)
  Eigen::Matrix<double, 11, 3> ux;
  ux.topRows<8>() = ue.topRows(8);
  Vec9 alpha = Eigen::Map<const Vec9>(committed_.data() + a0);
  Grad11 gx;
  Vec33 fx;
  Mat33 kx;
  MaterialResponse resp;
  // One pass over the points at alpha: fx = int G^T P dV, kx = int G^T A G dV (11 nodes), the
  // energy, the stresses, the trial histories, the round-off bounds; sets the stress scale
  // sum |P| |G| w of h and the round-off bound of h, sum dP |g_J| w (as the nodes' fabs).
  double scale = 0.0, h_round_off = 0.0;
  // ---- explicit steps (no element tangent wanted; bench/fem/bench_fem_explicit) ----
  // Only K_aa of kx is assembled (the 3 enhanced "nodes", the same entries, the same bits: the
  // local Newton is unchanged) and each point's tangent A is kept; the condensation's
  // K_ua d_alpha = sum_q w G_u^T A_q (G_a d_alpha) is then one product per point (below)
  // instead of K_ua assembled in every pass (its sums in another order: round-off of a
  // correction that is itself ~1e-10 of f). A point's tangent: 648 bytes on the stack.
  constexpr std::size_t kMaxExplicitPoints = 24;  // 2 x 2 x 6, the thin elements' rule
  const bool explicit_step = ke == nullptr && q1 - q0 <= kMaxExplicitPoints;
  std::array<Matrix9, kMaxExplicitPoints> point_tangent;
  Mat9 kaa;
  // ---- end explicit ----
  auto pass = [&]() {
    for (int jj = 0; jj < 3; ++jj) ux.row(8 + jj) = alpha.segment<3>(3 * jj).transpose();
    fx.setZero();
    if (explicit_step) {
      kaa.setZero();
    } else {
      kx.setZero();
    }
    fabs.setZero(8);
    energy = 0.0;
    scale = 0.0;
    h_round_off = 0.0;
    for (std::size_t q = q0; q < q1; ++q) {
      gx.topRows<8>() = Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>>(
          gradients_.data() + gradient_offset_[q]);
      gx.bottomRows<3>() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
          eas_gradients_.data() + eas_gradient_start_[e] + 9 * (q - q0));
      // F = I + sum_a u_a (x) grad_X N_a + sum_J alpha_J (x) g_J
      const Mat3 f = Mat3::Identity() + ux.transpose() * gx;
      if (!law.small_strain()) require_not_inverted(e, f.determinant());
      const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
      law.evaluate_step(f, std::span<const double>(committed_).subspan(s0, ns),
                        std::span<double>(trial_).subspan(s0, ns), step_, resp);
      const double w = weight_[q];
      // f_(a i) += P_iJ dG_a/dX_J w   (a over the 11 nodes)
      const Grad11 pg = gx * (resp.stress.transpose() * w);
      for (int a = 0; a < 11; ++a) fx.segment<3>(3 * a) += pg.row(a).transpose();
      // K_(a i)(b k) += dG_a/dX_J A_iJkL dG_b/dX_L w
      if (explicit_step) {
        add_material_stiffness(gx.bottomRows<3>(), resp.tangent, w, kaa);
        point_tangent[q - q0] = resp.tangent;
      } else {
        add_material_stiffness(gx, resp.tangent, w, kx);
      }
      const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
      const double* en = eas_norms_.data() + (eas_gradient_start_[e] / 9 + (q - q0)) * 2;
      scale += resp.stress.norm() * en[0] * w;
      energy += resp.energy_density * w;
      const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
      for (int a = 0; a < 8; ++a) fabs[a] += gn[a] * dp;
      h_round_off += en[1] * dp;
      const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
      const auto qi = static_cast<Eigen::Index>(q);
      cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
          sigma(0, 2);
      eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
    }
  };
  // local Newton on h(alpha) = int G_alpha^T P dV = 0:  K_aa d_alpha = -h, from the committed
  // alpha; each pass writes the energy, stresses and trial histories of its alpha, so the last
  // one's stay
  Eigen::PartialPivLU<Mat9> lu;
  Vec9 h;
  bool converged = false;
  // converged: |h| <= 1e-10 of its scale, or at its round-off (F = I + grad u is rounded to
  // eps |F|: at strains of 1e-8 that is 1e-8 of h's scale), or no longer decreasing within
  // 1e-6 of its scale (round-off the bound does not cover)
  double h_previous = 0.0;
  for (int it = 0; it < kMaxLocalIterations && !converged; ++it) {
    if (it > 0) alpha -= lu.solve(h);
    pass();
    h = fx.tail<9>();
    if (explicit_step) {
      lu.compute(kaa);
    } else {
      lu.compute(kx.bottomRightCorner<9, 9>());
    }
    const double hn = h.norm();
    converged = hn <= 1e-10 * scale + h_round_off || scale == 0.0 ||
                (it > 0 && hn > 0.5 * h_previous && hn <= 1e-6 * scale);
    h_previous = hn;
  }
  if (!converged) {
    std::ostringstream msg;
    msg << "EAS Hex8 element " << e << ": the enhanced strains did not converge in "
        << kMaxLocalIterations << " local iterations";
    throw Error(msg.str());
  }
  // f_e = f_u - K_ua K_aa^-1 h   (h ~ 0: the first-order correction of what is left); the trial
  // alpha likewise alpha - K_aa^-1 h
  const Vec9 d_alpha = lu.solve(h);
  Eigen::Map<Vec9>(trial_.data() + a0) = alpha - d_alpha;
  if (explicit_step) {
    // K_ua d_alpha = sum_q w G_u^T dP_q,  dP = A_q : dF_q,  dF = sum_J d_alpha_J (x) g_J
    fe.head<24>() = fx.head<24>();
    Eigen::Matrix<double, 3, 3> d_rows;  // row J: d_alpha_J
    for (int jj = 0; jj < 3; ++jj) d_rows.row(jj) = d_alpha.segment<3>(3 * jj).transpose();
    for (std::size_t q = q0; q < q1; ++q) {
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> ga(
          eas_gradients_.data() + eas_gradient_start_[e] + 9 * (q - q0));
      const Mat3 df = d_rows.transpose() * ga;
      Eigen::Matrix<double, 9, 1> dfv;  // 3 k + L
      for (int kk = 0; kk < 3; ++kk)
        for (int ll = 0; ll < 3; ++ll) dfv[3 * kk + ll] = df(kk, ll);
      const Eigen::Matrix<double, 9, 1> dpv = point_tangent[q - q0] * dfv;  // 3 i + J
      Mat3 dp;
      for (int i = 0; i < 3; ++i)
        for (int jj = 0; jj < 3; ++jj) dp(i, jj) = dpv[3 * i + jj] * weight_[q];
      const Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>> gu(
          gradients_.data() + gradient_offset_[q]);
      const Eigen::Matrix<double, 8, 3> pg = gu * dp.transpose();
      for (int a = 0; a < 8; ++a) fe.segment<3>(3 * a) -= pg.row(a).transpose();
    }
    return;
  }
  fe.head<24>() = fx.head<24>() - kx.topRightCorner<24, 9>() * d_alpha;
  if (ke == nullptr) return;
  // K_e = K_uu - K_ua K_aa^-1 K_au
  const Eigen::Matrix<double, 9, 24> kaa_kau = lu.solve(kx.bottomLeftCorner<9, 24>());
  ke->topLeftCorner<24, 24>() = kx.topLeftCorner<24, 24>() - kx.topRightCorner<24, 9>() * kaa_kau;
}

}  // namespace partita::fem
