#include "partita/fem/material_contribution.hpp"

#include <type_traits>

#include "material_contribution_kernels.hpp"

namespace partita::fem {

using detail::add_material_stiffness;
using detail::cauchy_stress_of;
using detail::evaluate_point;
using detail::stress_round_off;

// Full integration (the plain displacement elements: Tet4, Tet10, Hex20, and Hex8 when no other
// formulation is chosen): the full (stiffness) rule of each element,
//   F = I + sum_a u_a (x) grad_X N_a,   f_a,i = int_Omega0 P_iJ(F, history) dN_a/dX_J dV,
//   K_(a i)(b k) = int_Omega0 dN_a/dX_J A_iJkL dN_b/dX_L dV.
void MaterialContribution::evaluate_plain(std::size_t e, const ElementDisplacements& ue,
                                          ElementVector& fe, ElementMatrix* ke, double& energy,
                                          ElementVector& fabs) {
  const Element& el = mesh_.elements()[e];
  const int nn = node_count(el.type);
  const MaterialLaw& law = *element_law_[e];
  MaterialResponse resp;
  // N: the node count as a compile-time size (Hex8: fixed-size products, for the explicit
  // benchmark's speed) or Eigen::Dynamic (the other elements)
  auto points = [&]<int N>(std::integral_constant<int, N>) {
    constexpr int kMax = N == Eigen::Dynamic ? kMaxElementNodes : N;
    using Gradients = Eigen::Matrix<double, N, 3, Eigen::RowMajor, kMax, 3>;
    const Eigen::Matrix<double, N, 3, 0, kMax, 3> un = ue.topRows(nn);
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      const Eigen::Map<const Gradients> g(gradients_.data() + gradient_offset_[q], nn, 3);
      // F = I + sum_a u_a (x) grad_X N_a
      const Mat3 f = Mat3::Identity() + un.transpose() * g;
      if (!law.small_strain()) require_not_inverted(e, f.determinant());
      const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
      evaluate_point(law, f, std::span<const double>(committed_).subspan(s0, ns),
                     std::span<double>(trial_).subspan(s0, ns), step_, ke != nullptr, resp);
      const double w = weight_[q];
      energy += resp.energy_density * w;
      // f_a,i += P_iJ dN_a/dX_J w
      const Eigen::Matrix<double, N, 3, 0, kMax, 3> pg = g * (resp.stress.transpose() * w);
      for (int a = 0; a < nn; ++a) fe.segment<3>(3 * a) += pg.row(a).transpose();
      // round-off bound of those: |grad N_a| dP w
      const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
      const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
      for (int a = 0; a < nn; ++a) fabs[a] += gn[a] * dp;
      // sigma = P F^T / J for output (small-strain laws: sigma itself)
      const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
      const auto qi = static_cast<Eigen::Index>(q);
      cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
          sigma(0, 2);
      eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
      // K_(a i)(b k) += dN_a/dX_J A_iJkL dN_b/dX_L w
      if (ke != nullptr) add_material_stiffness(g, resp.tangent, w, *ke);
    }
  };
  if (nn == 8) {
    points(std::integral_constant<int, 8>{});
  } else {
    points(std::integral_constant<int, Eigen::Dynamic>{});
  }
}

}  // namespace partita::fem
