#pragma once
// Shared by the element formulations of MaterialContribution (one file each:
// material_contribution_full.cpp, _fbar.cpp, _eas.cpp, _reduced.cpp): the point-level pieces
// they all use.
#include <cmath>
#include <limits>
#include <span>

#include "partita/fem/material_law.hpp"
#include "partita/fem/material_response.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem::detail {

// ke_(a i)(b k) += scale dN_a/dX_J A_iJkL dN_b/dX_L: the material part of a point's stiffness,
// dF/du^T A dF/du with dF_iJ / du_bk = delta_ik dN_b/dX_J (g: n x 3 gradients); only the
// columns of the nodes b >= first_b (the others are left as they are).
template <typename Gradients, typename Matrix>
void add_material_stiffness(const Gradients& g, const Matrix9& a, double scale, Matrix& ke,
                            Eigen::Index first_b = 0) {
  Eigen::Matrix<double, 9, 3> ag;  // A_iJkL dN_b/dX_L for one node b: rows iJ, columns k
  const auto nn = g.rows();
  for (Eigen::Index b = first_b; b < nn; ++b) {
    for (int kk = 0; kk < 3; ++kk) {
      ag.col(kk) = a.middleCols<3>(3 * kk) * g.row(b).transpose() * scale;
    }
    for (Eigen::Index a_node = 0; a_node < nn; ++a_node) {
      for (int i = 0; i < 3; ++i) {
        ke.template block<1, 3>(3 * a_node + i, 3 * b) += g.row(a_node) * ag.middleRows<3>(3 * i);
      }
    }
  }
}

// The law at one point over the step: with its tangent (implicit paths) or without it
// (explicit steps).
inline void evaluate_point(const MaterialLaw& law, const Mat3& f, std::span<const double> committed,
                           std::span<double> trial, const MaterialStep& step, bool tangent,
                           MaterialResponse& r) {
  if (tangent) {
    law.evaluate_step(f, committed, trial, step, r);
  } else {
    law.evaluate_step_stress(f, committed, trial, step, r);
  }
}

// The Cauchy stress of a point for output: a small-strain law returns sigma itself (used as P
// by the operator), a finite-strain law P, whose Cauchy stress is sigma = P F^T / J.
inline Mat3 cauchy_stress_of(const MaterialLaw& law, const Mat3& p, const Mat3& f) {
  if (law.small_strain()) return p;
  return p * f.transpose() / f.determinant();
}

// Round-off bound of the stress of a point: eps (|P| + 3 A_max |F|). F = I + grad u is held to
// eps |F| (the identity dominates it at small strain), and the law's P = P(F) turns that into
// an error of about |A| eps |F| per component (3 terms per component, of at most A_max each).
inline double stress_round_off(const Mat3& p, const Mat3& f, double modulus) {
  return std::numeric_limits<double>::epsilon() * (p.norm() + 3.0 * modulus * f.norm());
}

}  // namespace partita::fem::detail
