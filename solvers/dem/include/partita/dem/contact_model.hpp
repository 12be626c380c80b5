#pragma once
// Hertz-Mindlin contact law for spheres against spheres, planes and triangles, and the table of
// per-material-pair parameters it reads.
//
// Effective quantities (REFERENCES.md): 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2,
// 1/G* = 2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2, R* = R1 R2/(R1+R2) (wall: R1),
// m* = m1 m2/(m1+m2) (wall: m1).

#include "partita/dem/damping_model.hpp"
#include "partita/dem/interaction.hpp"
#include "partita/dem/material.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#if defined(__GNUC__)
#define PARTITA_DEM_INLINE inline __attribute__((always_inline))
#else
#define PARTITA_DEM_INLINE inline
#endif

namespace partita::dem {

/// Everything the force law needs about one pair of materials, precomputed.
struct PairParameters {
  double e_star = 0.0;            ///< E* [Pa]
  double g_star = 0.0;            ///< G* [Pa]
  double zeta = 0.0;              ///< damping ratio: gamma = 2 zeta sqrt(S m*)
  double st_over_sn_sqrt = 0.0;   ///< sqrt(S_t/S_n) = sqrt(4 G*/E*)
  double friction = 0.0;          ///< mu
  double rolling_friction = 0.0;  ///< mu_r
  bool no_tension = true;         ///< clamp F_n >= 0
  /// Cap spring + damping tangential force at mu F_n (calibrated model); false: LIGGGHTS, which
  /// caps the spring only and adds the damping force while sticking.
  bool cap_total_tangential = true;
  bool defined = false;  ///< an interaction was given for this pair
};

/// Materials, interactions and the damping model; turns them into a PairParameters table.
class ContactModel {
 public:
  /// Adds a material and returns its id (0, 1, ...). Throws Error on non-physical values.
  int add_material(const Material& material);
  /// Sets the interaction of materials a and b (symmetric). Throws Error on unknown ids or
  /// values out of range.
  void set_interaction(int a, int b, const Interaction& interaction);
  void set_damping_model(DampingModel model);
  DampingModel damping_model() const { return damping_model_; }

  int material_count() const { return static_cast<int>(materials_.size()); }
  const Material& material(int id) const;
  /// Throws Error naming `what` if id is not a material id.
  void check_material(int id, const std::string& what) const;
  bool has_interaction(int a, int b) const;
  /// The interaction of materials a and b (valid when has_interaction(a, b)).
  const Interaction& interaction(int a, int b) const {
    return interactions_[a * material_count() + b];
  }

  /// Recomputes the pair table (restitution calibration) after changes; cheap when unchanged.
  void update();
  /// Parameters of the pair (a, b); valid after update().
  const PairParameters& pair(int a, int b) const { return table_[a * n_ + b]; }

 private:
  std::vector<Material> materials_;
  std::vector<Interaction> interactions_;  // n x n
  std::vector<bool> interaction_set_;      // n x n
  std::vector<PairParameters> table_;      // n_ x n_
  int n_ = 0;
  DampingModel damping_model_ = DampingModel::calibrated;
  bool dirty_ = true;
};

/// The dissipative parts of one contact's force in a force pass (energy accounting, System's
/// energies()): the dissipation is their power at the end-of-step velocities, which the integrator's
/// kick computes per particle (see System::Energies).
///   damping   normal damping force (F_n - F_elastic) n (with no tension: -F_elastic n where
///             the clamp acts) + tangential damping -gamma_t v_t while sticking
///   damping_t its tangential part (the caller's torques: -cr n x damping_t)
///   friction  the tangential force of a step in which it reached the Coulomb cap mu F_n (sliding:
///             all of it; zero while sticking)
///   spring    the tangential spring energy the cap released in that step:
///             1/2 S_t (|xi_before|^2 - |xi_after|^2), xi_before the history before this step's
///             increment; 0 while sticking
///   stiffening  minus the energy the tangential spring gained in the step without work: its
///             stiffness S_t = 8 G* sqrt(R* delta) changed with the overlap at a fixed history,
///             1/2 (S_t(delta + v_n dt) - S_t(delta)) |xi_before|^2, and the history lost its
///             part along the new normal, + 1/2 S_t (xi_before . n)^2 (Mindlin's incremental law
///             is not conservative: the spring's energy changes when the overlap changes or the
///             contact turns under a tangential load)
struct DissipativeParts {
  Eigen::Vector3d damping = Eigen::Vector3d::Zero();
  Eigen::Vector3d damping_t = Eigen::Vector3d::Zero();
  Eigen::Vector3d friction = Eigen::Vector3d::Zero();
  double spring = 0.0;
  double stiffening = 0.0;  ///< what the spring lost without work (below)
};

/// Hertz-Mindlin force on body i from body j (or a wall) for one contact with overlap delta > 0.
///   n      unit normal pointing from j (or the wall) to i
///   v_rel  v_i - v_j at the centres (wall: v_i - velocity of the wall at the contact point)
///   w_arm  cr_i omega_i + cr_j omega_j with cr = R - delta/2 (wall: cr_i omega_i)
///   shear  tangential displacement history, updated in place when update_history
/// Returns the normal force magnitude F_n; writes the total force on i and its tangential part.
/// parts (not null): also the dissipative parts (DissipativeParts); the force is the same bits.
/// plastic_growth: how much the contact's permanent overlap grew in this step (yield_overlap();
/// delta is then the elastic overlap): the elastic overlap before the step, from which the
/// stiffening term takes the tangential stiffness, is delta + v_n dt + that growth.
PARTITA_DEM_INLINE double hertz_mindlin(const PairParameters& p, double delta, double r_eff,
                                        double m_eff, const Eigen::Vector3d& n,
                                        const Eigen::Vector3d& v_rel, const Eigen::Vector3d& w_arm,
                                        Eigen::Vector3d& shear, double dt, bool update_history,
                                        Eigen::Vector3d& force, Eigen::Vector3d& f_tangential,
                                        DissipativeParts* parts = nullptr,
                                        double plastic_growth = 0.0) {
  // Normal: F_n = 4/3 E* sqrt(R*) delta^(3/2) - gamma_n v_n, S_n = 2 E* sqrt(R* delta),
  // gamma_n = 2 zeta sqrt(S_n m*) (v_n < 0 while approaching).
  const double a = std::sqrt(r_eff * delta);  // contact radius
  const double s_n = 2.0 * p.e_star * a;
  const double v_n = v_rel.dot(n);
  double f_n = (2.0 / 3.0) * s_n * delta;
  // gamma_n = 2 zeta sqrt(S_n m*); gamma_t = gamma_n sqrt(S_t/S_n)
  const double gamma_n = p.zeta > 0.0 ? 2.0 * p.zeta * std::sqrt(s_n * m_eff) : 0.0;
  f_n -= gamma_n * v_n;
  if (p.no_tension && f_n < 0.0) f_n = 0.0;
  force = f_n * n;
  if (parts) {
    parts->damping = (f_n - (2.0 / 3.0) * s_n * delta) * n;
    parts->damping_t.setZero();
    parts->friction.setZero();
    parts->spring = 0.0;
    parts->stiffening = 0.0;
  }
  if (p.friction <= 0.0) {
    f_tangential.setZero();
    shear.setZero();
    return f_n;
  }
  // Tangential (Mindlin, no-slip stiffness): S_t = 8 G* sqrt(R* delta); history xi integrates
  // the tangential velocity at the contact point and is kept in the current tangent plane:
  //   v_t = v_rel - v_n n + n x w_arm,  xi += v_t dt,  xi -= (xi.n) n,
  //   F_t = -S_t xi - gamma_t v_t,  gamma_t = 2 zeta sqrt(S_t m*),
  //   |F_t| <= mu |F_n|: when above, F_t is scaled to the cap and the spring takes all of it,
  //   xi = -F_t/S_t. LIGGGHTS variant: the test is on the spring force alone and the damping is
  //   added unchecked while sticking (which lets F_t exceed the cap at the start of a contact).
  const Eigen::Vector3d v_t = v_rel - v_n * n + n.cross(w_arm);
  const double before2 = parts ? shear.squaredNorm() : 0.0;
  const double xn_before = parts ? shear.dot(n) : 0.0;
  if (update_history) {
    shear += v_t * dt;
    shear -= shear.dot(n) * n;
  }
  const double k_t = 8.0 * p.g_star * a;
  // (energy) what the spring's energy did without work over the step: its stiffness changed
  // with the overlap (from S_t(delta + v_n dt) to S_t(delta) at the history before the step) and
  // the history lost its part along the new normal
  double stiffening = 0.0;
  if (parts) {
    double before = delta + v_n * dt;
    if (plastic_growth != 0.0) before += plastic_growth;
    const double delta_before = std::max(0.0, before);
    const double k_before = 8.0 * p.g_star * std::sqrt(r_eff * delta_before);
    stiffening = 0.5 * (k_before - k_t) * before2 + 0.5 * k_t * xn_before * xn_before;
  }
  if (p.cap_total_tangential) {
    f_tangential = -k_t * shear - (gamma_n * p.st_over_sn_sqrt) * v_t;
    const double ft2 = f_tangential.squaredNorm();
    const double cap = p.friction * f_n;
    if (ft2 > cap * cap) {
      f_tangential *= cap / std::sqrt(ft2);
      if (update_history) shear = f_tangential / (-k_t);
      if (parts) {
        parts->friction = f_tangential;
        parts->spring = 0.5 * k_t * (before2 - shear.squaredNorm());
      }
    } else if (parts) {
      parts->spring = 0.0;
      parts->damping_t = -(gamma_n * p.st_over_sn_sqrt) * v_t;
      parts->damping += parts->damping_t;
    }
    if (parts) parts->stiffening = stiffening;
    force += f_tangential;
    return f_n;
  }
  const double shear2 = shear.squaredNorm();
  const double ft_cap = p.friction * std::abs(f_n);
  if (k_t * k_t * shear2 > ft_cap * ft_cap) {  // |F_spring| > cap, without a square root
    if (shear2 > 0.0) {
      const double ratio = ft_cap / (k_t * std::sqrt(shear2));
      f_tangential = (-k_t * ratio) * shear;
      if (update_history) shear *= ratio;
    } else {
      f_tangential.setZero();
    }
    if (parts) {
      parts->friction = f_tangential;
      parts->spring = 0.5 * k_t * (before2 - shear.squaredNorm());
    }
  } else {
    f_tangential = -k_t * shear - (gamma_n * p.st_over_sn_sqrt) * v_t;
    if (parts) {
      parts->damping_t = -(gamma_n * p.st_over_sn_sqrt) * v_t;
      parts->damping += parts->damping_t;
    }
  }
  if (parts) parts->stiffening = stiffening;
  force += f_tangential;
  return f_n;
}

/// Particles that yield in their contacts with each other (StepHook::contact_yield()): a pair
/// with a yielding particle holds its mean Hertz pressure F/(pi a^2) at the yield pressure, the
/// overlap beyond becoming the pair's permanent overlap (PairContacts). The force pass hands the
/// pair kernels this (nullptr: no particle yields).
struct PairYield {
  const double* pressure;  ///< per particle: the yield pressure [Pa] (<= 0: none)
  double below_diameter;   ///< it applies to particles with 2 r below this [m]
  float* plastic;          ///< per pair slot: the permanent overlap [m]
  // A pair of which neither particle is below below_diameter never yields, so its permanent
  // overlap is 0 (a new pair's slot starts at 0): the kernels skip such pairs' slots.
};

/// The yield pressure of a pair whose particles yield at pi and pj (<= 0: that one does not):
/// the weaker of the two that yield, 0 when neither does.
inline double pair_yield_pressure(double pi, double pj) {
  return pi > 0.0 && pj > 0.0 ? std::min(pi, pj) : std::max(pi, std::max(pj, 0.0));
}

/// An elastic-perfectly plastic contact (Thornton 1997 with the mean contact pressure limited to
/// p_y): the overlap delta of a contact of effective radius r_eff whose permanent part is
/// `plastic` (followed down where delta is smaller: the surfaces have parted that far) is
/// elastic up to delta_y = r_eff (3 pi p_y / (4 E*))^2 (the overlap at which the mean Hertz
/// pressure 4 E* sqrt(delta) / (3 pi sqrt(r_eff)) reaches p_y); beyond it the permanent overlap
/// grows to delta - delta_y and the elastic force F_y = 4/3 E* sqrt(r_eff) delta_y^(3/2) does the
/// work F_y x its growth (added to *work). Returns the elastic overlap (>= 0); p_y <= 0: no
/// yield (the permanent overlap only followed down). The permanent overlap grows by yielding
/// to at most max_plastic (a larger one carried in, such as a pre-overlap, is kept): beyond it
/// the contact is elastic again, its Hertz force growing with delta - max_plastic. The
/// permanent overlap is a float (a pair's or a mesh contact's 4 bytes); the work is taken on the
/// stored values.
inline double yield_overlap(double delta, double r_eff, double e_star, double p_y, float& plastic,
                            double* work,
                            double max_plastic = std::numeric_limits<double>::infinity()) {
  float pl = std::min(plastic, static_cast<float>(delta));
  double elastic = pl > 0.0f ? std::max(0.0, delta - static_cast<double>(pl)) : delta;
  if (p_y > 0.0) {
    const double root = 0.75 * std::numbers::pi * p_y / e_star;
    const double delta_y = r_eff * root * root;
    if (elastic > delta_y) {
      float yielded = static_cast<float>(delta - delta_y);
      const bool capped = static_cast<double>(yielded) > max_plastic;
      if (capped) yielded = std::max(pl, static_cast<float>(max_plastic));
      if (!capped || yielded > pl) {
        if (work != nullptr)
          *work += (4.0 / 3.0) * e_star * std::sqrt(r_eff) * delta_y * std::sqrt(delta_y) *
                   (static_cast<double>(yielded) - static_cast<double>(pl));
        pl = yielded;
        elastic = std::max(0.0, delta - static_cast<double>(pl));
      }
    }
  }
  plastic = pl;
  return elastic;
}

/// The elastic part of a contact's overlap delta whose permanent part is `plastic` (followed
/// down where delta is smaller, as yield_overlap() does).
inline double elastic_overlap(double delta, double plastic) {
  return plastic > 0.0 ? std::max(0.0, delta - std::min(plastic, delta)) : delta;
}

/// Elastic energy stored in a Hertz contact: integral of 4/3 E* sqrt(R*) d^(3/2) from 0 to delta
/// = 8/15 E* sqrt(R*) delta^(5/2), plus the tangential spring 1/2 S_t |xi|^2.
inline double hertz_elastic_energy(const PairParameters& p, double delta, double r_eff,
                                   const Eigen::Vector3d& shear) {
  const double a = std::sqrt(r_eff * delta);
  return 8.0 / 15.0 * p.e_star * a * delta * delta + 0.5 * 8.0 * p.g_star * a * shear.squaredNorm();
}

}  // namespace partita::dem
