#include "partita/fem/material_contribution.hpp"

#include "partita/fem/error.hpp"
#include "partita/fem/shape_functions.hpp"

#include "material_contribution_kernels.hpp"

namespace partita::fem {

using detail::add_material_stiffness;
using detail::cauchy_stress_of;
using detail::evaluate_point;
using detail::stress_round_off;

// ---- reduced Hex8 (Hex8Formulation::Reduced): the explicit plate element ----
// Points: one in the plane, a line through the thickness (thickness_line_rule). The line sees
// every displacement mode of the Hex8 but the two hourglass modes h_1 = xi eta and
// h_4 = xi eta zeta (xi, eta in the plane, zeta through the thickness) in each of the three
// components: their gradients vanish on the line. These get the stabilisation of Flanagan &
// Belytschko (IJNME 17, 1981, 679-706): the projections gamma = h - G0 (X^T h) (G0 the
// gradients at the centre, X the nodes' coordinates) are orthogonal to every linear field (so
// the patch test and rigid motions, rotations of any size included, give no hourglass force),
// hourglass "strains" q_alpha = U^T gamma_alpha (3-vectors) and forces f_a = gamma_alpha,a
// K_alpha q_alpha. The stiffnesses K_alpha are those of the assumed strains of Belytschko &
// Bindeman (CMAME 105, 1993, 225-260): the energy of the mode's normal strains, which is that
// of bending in the plane (h_1 in the in-plane components: exact for a rectangle) and of the
// thickness strain's xi eta variation (h_4 normal to the plane), without the shear strains
// whose integration would lock:
//   K_1 = V / 192 E' (g_xi g_xi^T + g_eta g_eta^T),
//   K_4 = V / 576 [E' (g_xi g_xi^T + g_eta g_eta^T) + (lambda + 2 mu) g_zeta g_zeta^T],
// g the gradients of the parametric coordinates at the centre, n the plate's normal,
// E' = 4 mu (lambda + mu) / (lambda + 2 mu) the plate modulus. The line misses one more
// displacement mode: a rotation about the normal that varies through the thickness
// (u = zeta (-eta, xi, 0): torsion), whose strains are transverse shears that vary in the plane.
// So the transverse shears' in-plane variations, s_eta = d gamma_(xi n) / d eta and
// s_xi = d gamma_(eta n) / d xi at the centre (computed from the projected vectors), get their
// energy int mu (eta s_eta)^2 + mu (xi s_xi)^2 dV = mu V / 3 (s_eta^2 + s_xi^2): the part of the
// transverse shear that assumed-natural-strain plates keep (MITC4: gamma_(xi n) linear in eta),
// zero for a Kirchhoff twist (its rotations and w = xi eta cancel), while d gamma_(xi n) / d xi,
// which would lock in bending, is left out. This also holds w = xi eta (h_1 normal to the
// plane). The hourglass forces are elastic (as LS-DYNA's stiffness forms), in the reference frame
// (total Lagrangian: exact for rigid rotations, approximate for large rotations with hourglass
// deformation).
// Poisson thickness locking: with one element through the thickness the displacement field's
// thickness strain is constant through it, so bending (whose Poisson contraction varies
// linearly through it) would see a plane-strain modulus (+10 % at nu = 0.3). One enhanced
// strain (Simo & Armero 1992; the thickness mode of the solid-shells of Hauptmann &
// Schweizerhof, IJNME 42, 1998, 49-69) adds F += beta (j0 / j) zeta n (x) c, c = grad zeta at the
// centre (int over the element = 0: the patch test holds). Explicit steps update it once per
// step with the elastic K_bb = (lambda + 2 mu) |c|^2 sum_q w_q ((j0 / j) zeta_q)^2 (factorised at
// construction; the law called without its tangent):
//   beta_n+1 = beta_n - h(u_n+1, beta_n) / K_bb,  h = sum_q w_q n . P_q c (j0 / j) zeta_q,
// so h goes to zero with the steps (exactly for a linear law, geometrically while plastic flow
// softens the thickness stiffness).
void MaterialContribution::setup_reduced_hex8(const ElementCoordinates& x, int thickness_axis,
                                              const Mat3& j0_inv, const Vec3& elastic) {
  static constexpr double kCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                           {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int k = thickness_axis, i = (k + 1) % 3, j = (k + 2) % 3;
  ShapeVector n;
  ShapeGradient g;
  physical_gradients(ElementType::Hex8, x, Vec3::Zero(), n, g);
  const Eigen::Matrix<double, 8, 3> g0 = g.topRows(8);
  const Eigen::Matrix<double, 8, 3> xe = x.topRows(8);
  Eigen::Matrix<double, 8, 1> h1, h4;
  for (int a = 0; a < 8; ++a) {
    h1[a] = kCorner[a][i] * kCorner[a][j];
    h4[a] = h1[a] * kCorner[a][k];
  }
  // gamma = v - G0 (X^T v): orthogonal to every linear field (X^T G0 = I, sum_a G0_a = 0)
  auto project = [&](const Eigen::Matrix<double, 8, 1>& v) -> Eigen::Matrix<double, 8, 1> {
    return v - g0 * (xe.transpose() * v);
  };
  Eigen::Matrix<double, 8, 1> h_jk, h_ik;  // eta zeta, xi zeta (xi = axis i, eta = axis j)
  for (int a = 0; a < 8; ++a) {
    h_jk[a] = kCorner[a][j] * kCorner[a][k];
    h_ik[a] = kCorner[a][i] * kCorner[a][k];
  }
  const Eigen::Matrix<double, 8, 1> gamma1 = project(h1), gamma4 = project(h4);
  const Eigen::Matrix<double, 8, 1> gamma_jk = project(h_jk), gamma_ik = project(h_ik);
  const Vec3 gi = j0_inv.row(i).transpose(), gj = j0_inv.row(j).transpose(),
             gk = j0_inv.row(k).transpose();
  const Vec3 normal = gk.normalized(), ti = gi.normalized(), tj = gj.normalized();
  const double l2m = elastic[0], lambda = elastic[1], mu = elastic[2];
  const double plate = l2m - lambda * lambda / l2m;
  const std::size_t q0 = qp_offset_.back(), q1 = weight_.size();
  double volume = 0.0, beta = 0.0;
  for (std::size_t q = q0; q < q1; ++q) {
    volume += weight_[q];
    beta += weight_[q] * reduced_point_scale_[q] * reduced_point_scale_[q];
  }
  const Mat3 membrane = plate * (gi * gi.transpose() + gj * gj.transpose());
  const Mat3 k1 = volume / 192.0 * membrane;
  const Mat3 k4 = volume / 576.0 * (membrane + l2m * gk * gk.transpose());
  const double k_beta = l2m * gk.squaredNorm() * beta;
  // the transverse shears' in-plane variation: s_eta = d gamma_(xi n) / d eta and
  // s_xi = d gamma_(eta n) / d xi at the centre, s = sum_a c_a . u_a with
  // d grad N_a / d eta = (gamma1_a g_xi + gamma_jk_a g_zeta) / 8 (and i <-> j)
  Eigen::Matrix<double, 8, 3> c_eta, c_xi;
  for (int a = 0; a < 8; ++a) {
    const Vec3 b_eta = (gamma1[a] * gi + gamma_jk[a] * gk) / 8.0;
    const Vec3 b_xi = (gamma1[a] * gj + gamma_ik[a] * gk) / 8.0;
    c_eta.row(a) = (ti * normal.dot(b_eta) + normal * ti.dot(b_eta)).transpose();
    c_xi.row(a) = (tj * normal.dot(b_xi) + normal * tj.dot(b_xi)).transpose();
  }
  for (int a = 0; a < 8; ++a) reduced_data_.push_back(gamma1[a]);
  for (int a = 0; a < 8; ++a) reduced_data_.push_back(gamma4[a]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) reduced_data_.push_back(k1(r, c));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) reduced_data_.push_back(k4(r, c));
  for (int d = 0; d < 3; ++d) reduced_data_.push_back(gk[d]);
  for (int d = 0; d < 3; ++d) reduced_data_.push_back(normal[d]);
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) reduced_data_.push_back(c_eta(a, d));
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) reduced_data_.push_back(c_xi(a, d));
  // int mu (eta s_eta)^2 dV = mu V / 3 s_eta^2
  reduced_data_.push_back(mu * volume / 3.0);
  reduced_data_.push_back(1.0 / k_beta);
}

void MaterialContribution::evaluate_reduced(std::size_t e, const ElementDisplacements& ue,
                                            ElementVector& fe, ElementMatrix* ke,
                                            double& energy, ElementVector& fabs) {
  if (ke != nullptr)
    throw Error(
        "the reduced Hex8 (hex8: reduced) has no tangent: it is an element of central-difference "
        "analyses (without stiffness-proportional Rayleigh damping); static and Newmark "
        "analyses use the EAS Hex8 (hex8: incompatible-modes)");
  using Gradients = Eigen::Matrix<double, 8, 3, Eigen::RowMajor>;
  const MaterialLaw& law = *element_law_[e];
  const double* data = reduced_data_.data() + reduced_start_[e];
  const Eigen::Map<const Eigen::Matrix<double, 8, 1>> gamma1(data), gamma4(data + 8);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> k1(data + 16), k4(data + 25);
  const Eigen::Map<const Vec3> c(data + 34), normal(data + 37);
  const Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>> c_eta(data + 40),
      c_xi(data + 64);
  const double k_shear = data[88];
  const double k_beta_inverse = data[89];
  const std::size_t a0 = eas_offset_[e];
  const double beta = committed_[a0];
  const Eigen::Matrix<double, 8, 3> un = ue.topRows(8);
  const Mat3 enhanced = beta * normal * c.transpose();
  MaterialResponse resp;
  Eigen::Matrix<double, 8, 3> forces = Eigen::Matrix<double, 8, 3>::Zero();
  double h = 0.0;
  for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
    const Eigen::Map<const Gradients> g(gradients_.data() + gradient_offset_[q]);
    const double zeta = reduced_point_scale_[q];
    // F = I + sum_a u_a (x) grad_X N_a + beta (j0 / j) zeta n (x) c
    const Mat3 f = Mat3::Identity() + un.transpose() * g + zeta * enhanced;
    if (!law.small_strain()) require_not_inverted(e, f.determinant());
    const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
    law.evaluate_step_stress(f, std::span<const double>(committed_).subspan(s0, ns),
                             std::span<double>(trial_).subspan(s0, ns), step_, resp);
    const double w = weight_[q];
    energy += resp.energy_density * w;
    forces.noalias() += g * (resp.stress.transpose() * w);
    h += w * zeta * normal.dot(resp.stress * c);
    const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
    const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
    for (int a = 0; a < 8; ++a) fabs[a] += gn[a] * dp;
    const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
    const auto qi = static_cast<Eigen::Index>(q);
    cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
        sigma(0, 2);
    eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
  }
  trial_[a0] = beta - h * k_beta_inverse;
  // the enhanced strain's work since the last evaluation: -1/2 (h_k + h_k+1)(beta_k - beta_k-1),
  // beta_k - beta_k-1 = -h_k / K_bb (enhanced_strain_work())
  const double h_before = committed_[a0 + 1];
  trial_[a0 + 1] = h;
  enhanced_work_trial_[e] = 0.5 * (h_before + h) * h_before * k_beta_inverse;
  // hourglass: q_alpha = U^T gamma_alpha, f_a += gamma_alpha,a K_alpha q_alpha
  const Vec3 q1 = un.transpose() * gamma1, q4 = un.transpose() * gamma4;
  const Vec3 p1 = k1 * q1, p4 = k4 * q4;
  forces.noalias() += gamma1 * p1.transpose() + gamma4 * p4.transpose();
  // transverse shear's in-plane variation: f_a += k_s (s_eta c_eta,a + s_xi c_xi,a)
  const double s_eta = (c_eta.array() * un.array()).sum(), s_xi = (c_xi.array() * un.array()).sum();
  forces.noalias() += k_shear * (s_eta * c_eta + s_xi * c_xi);
  energy += 0.5 * (q1.dot(p1) + q4.dot(p4) + k_shear * (s_eta * s_eta + s_xi * s_xi));
  for (int a = 0; a < 8; ++a) fe.segment<3>(3 * a) = forces.row(a).transpose();
}

}  // namespace partita::fem
