#pragma once
// The time integrator of the particles: velocity Verlet on a packed working copy of the moving
// state.
//
//   first half  v += dt/2 F/m,  x += dt v,  omega += dt/2 T/I      (F, T of the last force pass)
//   forces at t + dt
//   kick        v += dt/2 F/m,  omega += dt/2 T/I                  (F, T of this force pass)
//
// with I = 2/5 m R^2 unless the caller set another (System::set_particle_mass()).
//
// VelocityVerlet owns the packed state (PackedParticle: x, v, omega, the force and torque sums
// and the radius a contact kernel reads about a neighbour: 128 bytes, two aligned cache lines
// instead of one or two per array) and its mirror logic: positions, velocities, angular
// velocities, forces and torques live in the packed copy while stepping, the particle store's
// arrays are brought up to date on demand (sync()), and the packed copy is loaded again (load())
// after the caller changed the store (invalidate()).
// The per-particle operations are inline members of a Pass (raw pointers taken once per loop), so
// that System's fused parallel loops (one parallel region per step: first half, forces and kick
// particle by particle as each force sum completes) call them without a loop of their own.

#include "partita/dem/contact_model.hpp"  // PARTITA_DEM_INLINE
#include "partita/dem/packed_particle.hpp"
#include "partita/dem/particles.hpp"

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class VelocityVerlet {
 public:
  /// Whether the packed copy holds the store's current state (false after invalidate()).
  bool loaded() const { return loaded_; }
  /// Copies the store's state into the packed arrays (sized to the store; no allocation when
  /// the particle count is unchanged); the store's copies are then current.
  void load(const Particles& p);
  /// The caller changed the store (particles added, removed, renumbered, velocities or masses
  /// set, a state restored): the next step loads the packed copy again.
  void invalidate() {
    loaded_ = false;
    has_motion_ = false;
  }
  /// The packed state is about to move on (a step, a force pass): the store's copies are stale
  /// until sync().
  void moved() { mirror_current_ = false; }
  /// Brings the store's positions, velocities, angular velocities, forces and torques up to date
  /// (cheap when they are).
  void sync(Particles& p) const {
    if (!mirror_current_) copy_back(p);
  }
  /// The packed state while it is ahead of the store's copies (stepping, no sync() since), else
  /// nullptr (the store's copies are current): for reading x, v, omega without a sync().
  const PackedParticle* ahead() const { return mirror_current_ ? nullptr : packed_.data(); }
  /// The store's copies are current (a state was read into the store): nothing to sync, and the
  /// packed copy is loaded again before the next use.
  void store_replaced() {
    mirror_current_ = true;
    loaded_ = false;
    has_motion_ = false;
  }

  /// What the last step left to bound the next one's motion, so that System::step() can tell
  /// before a step that its first half moves no particle beyond the neighbour lists' skin:
  /// moved, the largest distance of a particle from its position at the last list build; speed,
  /// the largest |v|; accel, the largest |F|/m; extent, the largest |x| component. The next
  /// first half moves a particle by dt |v + dt/2 F/m| <= dt (speed + dt/2 accel). Forgotten with
  /// the packed copy (load(), invalidate(), store_replaced()) and by forget_motion().
  struct Motion {
    double moved = 0.0, speed = 0.0, accel = 0.0, extent = 0.0;
  };
  bool has_motion() const { return has_motion_; }
  const Motion& motion() const { return motion_; }
  void set_motion(const Motion& m) {
    motion_ = m;
    has_motion_ = true;
  }
  void forget_motion() { has_motion_ = false; }

  const PackedParticle& particle(std::size_t i) const { return packed_[i]; }
  PackedParticle& particle(std::size_t i) { return packed_[i]; }

  /// What one loop over the particles reads and writes, taken once per loop (raw pointers the
  /// loop keeps in registers).
  struct Pass {
    PackedParticle* packed;
    const double* mass;
    const double* inertia;

    /// First half of the step for particle i with the forces of the last pass: v += half F/m,
    /// x += dt v, omega += half T/I (half = dt/2). Returns the new position.
    PARTITA_DEM_INLINE const Eigen::Vector3d& first_half(int i, double dt, double half) const {
      PackedParticle& q = packed[i];
      q.v += (half / mass[i]) * q.f;
      q.x += dt * q.v;
      q.w += (half / inertia[i]) * q.t;
      return q.x;
    }
    /// Closing kick of particle i with its complete force f and torque t of this pass:
    /// v += kick f/m, omega += kick t/I (kick = dt/2).
    PARTITA_DEM_INLINE void kick(int i, double kick, const Eigen::Vector3d& f,
                                 const Eigen::Vector3d& t) const {
      PackedParticle& q = packed[i];
      q.v += (kick / mass[i]) * f;
      q.w += (kick / inertia[i]) * t;
    }
  };
  /// The pass over the packed state; masses and inertias from the store's arrays.
  Pass pass(const Particles& p) { return Pass{packed_.data(), p.mass.data(), p.inertia.data()}; }

 private:
  void copy_back(Particles& p) const;

  std::vector<PackedParticle> packed_;  // the moving state while stepping
  bool loaded_ = false;                 // packed_ holds the store's current state
  bool has_motion_ = false;             // motion_ bounds the current state's next step
  Motion motion_;
  mutable bool mirror_current_ = true;  // the store's x, v, omega, F, T equal packed_'s
};

}  // namespace partita::dem
