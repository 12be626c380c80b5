#pragma once
// A servo-controlled plane wall (a lid pressed onto a bed to a target force): after every step
// the wall's velocity along its normal is set from the normal force the particles exerted on it
// in that step,
//   v = clamp(gain (F_target - F_n), -max_velocity, max_velocity),   velocity = v n,
// n the plane's unit normal (pointing to the particles' side), F_n = -F_wall . n >= 0 the force
// with which the particles push the wall back. Below the target the wall advances towards the
// particles, above it retreats; at rest F_n = F_target. The velocity is the plane's own (saved
// with the system's state), so a restart or a repeated window continues bit for bit; the hook
// itself keeps no state. Proportional control: choose max_velocity small against the bed's
// wave speed (a quasi-static approach) and gain so that gain * F_target is about max_velocity
// (full speed far from the target).

#include <memory>
#include <string>

#include <Eigen/Core>

#include "partita/dem/step_hook.hpp"

namespace partita::dem {

struct WallServoParameters {
  int wall = -1;                                      ///< a plane wall (System::add_plane)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< the plane's normal, to the particles
  double force = 0.0;         ///< target normal force F_target [N], > 0
  double max_velocity = 0.0;  ///< [m/s], > 0
  double gain = 0.0;          ///< [m/(s N)], > 0
};

class WallServo final : public StepHook {
 public:
  /// Throws Error on a non-positive force, velocity or gain, or a zero or non-finite normal.
  explicit WallServo(const WallServoParameters& p);
  std::string name() const override { return "wall-servo"; }
  std::unique_ptr<StepHook> clone() const override { return std::make_unique<WallServo>(*this); }
  /// Throws Error unless the wall exists.
  void attach(System& system) override;
  void end_of_step(System& system, double dt) override;
  /// F_n = -F_wall . n: the normal force the particles exerted on the wall in the last step [N].
  double normal_force(const System& system) const;
  const WallServoParameters& parameters() const { return p_; }

 private:
  WallServoParameters p_;
};

}  // namespace partita::dem
