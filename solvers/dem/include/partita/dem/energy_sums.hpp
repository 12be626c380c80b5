#pragma once
// What the force pass gathers for the energy accounting (System::energies()): per particle, the
// sums of the dissipative parts of its contact forces and torques (DissipativeParts), which the
// integrator's kick multiplies by the end-of-step velocities; per block of particles, the
// energies of the pass, summed over the blocks in a fixed order after it (the same bits on any
// number of threads).

#include <Eigen/Core>

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
};

/// Per block of particles, one pass: dissipation by damping and friction and the work of gravity
/// [J] (kick: power at the end-of-step velocities times dt).
struct BlockEnergy {
  double damping = 0.0, friction = 0.0, gravity = 0.0, stiffening = 0.0;
};

}  // namespace partita::dem
