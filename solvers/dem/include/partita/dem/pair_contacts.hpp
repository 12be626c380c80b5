#pragma once
// Contacts between two spheres: the force kernel of one listed pair (Hertz-Mindlin with the
// tangential history, torques, rolling resistance and the contact load of the breakage
// criterion). The per-pair state, the tangential history and the touching flag, lives in the
// slot of the pair in the neighbour list (NeighborList moves it to the pair's new slot at a
// rebuild and renumbers it with the particles); the material-pair parameters in the
// ContactModel's table. Inline: the force pass keeps the compiler's whole view of the loop.

#include "partita/dem/contact_model.hpp"
#include "partita/dem/packed_particle.hpp"

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace partita::dem {

class PairContacts {
 public:
  /// Force of the pair (i, j) on i and the torques on i and j; false (and the history settled:
  /// zeroed once the spheres part) when they do not overlap. Torques T_i = -cr_i n x F_t,
  /// T_j = -cr_j n x F_t (cr = R - delta/2, LIGGGHTS convention), rolling resistance
  /// T_i = -mu_r F_n R* w_rel/|w_rel| = -T_j (w_rel = omega_i - omega_j).
  /// Load: also the contact load F_n (E*/R*)^2 (breakage criterion, System::contact_load()).
  template <bool Load>
  static PARTITA_DEM_INLINE bool force(const ContactModel& model, const PackedParticle& qi,
                                       const PackedParticle& qj, Eigen::Vector3d& shear,
                                       char& touching, double dt, bool update_history,
                                       Eigen::Vector3d& fij, Eigen::Vector3d& ti,
                                       Eigen::Vector3d& tj, double& load) {
    const Eigen::Vector3d d = qi.x - qj.x;
    const double ri = qi.r, rj = qj.r;
    const double rsum = ri + rj;
    const double r2 = d.squaredNorm();
    if (r2 >= rsum * rsum) {
      if (touching) {
        touching = 0;
        shear.setZero();
      }
      return false;
    }
    touching = 1;
    const double r = std::sqrt(r2);
    const Eigen::Vector3d nrm =
        r > 0.0 ? Eigen::Vector3d(d * (1.0 / r)) : Eigen::Vector3d::UnitZ();
    const double delta = rsum - r;
    const double mi = qi.m, mj = qj.m;
    const PairParameters& pp = model.pair(qi.material, qj.material);
    const double r_eff = ri * rj / rsum;
    const double m_eff = mi * mj / (mi + mj);
    const double cri = ri - 0.5 * delta, crj = rj - 0.5 * delta;
    const Eigen::Vector3d w_arm = cri * qi.w + crj * qj.w;
    Eigen::Vector3d ft;
    const double fn = hertz_mindlin(pp, delta, r_eff, m_eff, nrm, qi.v - qj.v, w_arm, shear, dt,
                                    update_history, fij, ft);
    if constexpr (Load) {
      const double k = pp.e_star / r_eff;
      load = fn * k * k;
    }
    const Eigen::Vector3d c = nrm.cross(ft);
    ti = -cri * c;
    tj = -crj * c;
    if (pp.rolling_friction > 0.0) {
      const Eigen::Vector3d w_rel = qi.w - qj.w;
      const double wn = w_rel.norm();
      if (wn > 0.0) {
        const Eigen::Vector3d tr = (-pp.rolling_friction * std::abs(fn) * r_eff / wn) * w_rel;
        ti += tr;
        tj -= tr;
      }
    }
    return true;
  }
};

}  // namespace partita::dem
