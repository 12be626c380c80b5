#pragma once
// What the force pass gathers for the energy accounting (System::energies()): per particle, the
// sums of the dissipative parts of its contact forces and torques (DissipativeParts), which the
// integrator's kick multiplies by the end-of-step velocities; per block of particles, the
// energies of the pass, summed over the blocks in a fixed order after it (the same bits on any
// number of threads).

#include "partita/dem/contact_model.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace partita::dem {

/// Per particle: damping force and torque, friction force and torque of the current pass.
struct DissipationSums {
  Eigen::Vector3d fd, td, ff, tf;
  void clear() {
    fd.setZero();
    td.setZero();
    ff.setZero();
    tf.setZero();
  }
};

/// What a particle's wall and mesh contacts add besides their forces: sum of f_d . v_wall and
/// f_f . v_wall (the walls' share of the dissipative forces' power, taken off again: the
/// dissipation is the power on the relative motion) and the spring energy the friction caps
/// released, and the stiffening terms (DissipativeParts).
struct WallDissipation {
  double damping = 0.0, friction = 0.0, spring = 0.0, stiffening = 0.0;
  double plastic = 0.0;  ///< work of yielding mesh contacts (an energy, not a power) [J]
};

/// A wall or mesh contact's dissipative parts (normal n, arm cr, the wall's velocity at the
/// contact point v_wall) into the particle's sums and its wall terms.
PARTITA_DEM_INLINE void add_wall_parts(const DissipativeParts& parts, const Eigen::Vector3d& n,
                                       double cr, const Eigen::Vector3d& v_wall,
                                       DissipationSums& sums, WallDissipation& wd) {
  sums.fd += parts.damping;
  sums.td -= cr * n.cross(parts.damping_t);
  sums.ff += parts.friction;
  sums.tf -= cr * n.cross(parts.friction);
  wd.damping += parts.damping.dot(v_wall);
  wd.friction += parts.friction.dot(v_wall);
  wd.spring += parts.spring;
  wd.stiffening += parts.stiffening;
}

/// Per block of particles, one pass: dissipation by damping and friction and the work of gravity
/// [J] (kick: power at the end-of-step velocities times dt).
struct BlockEnergy {
  double damping = 0.0, friction = 0.0, gravity = 0.0, stiffening = 0.0;
};

}  // namespace partita::dem
