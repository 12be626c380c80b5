#include "partita/dem/wall_servo.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "partita/dem/error.hpp"
#include "partita/dem/system.hpp"

namespace partita::dem {

WallServo::WallServo(const WallServoParameters& p) : p_(p) {
  std::ostringstream msg;
  if (!(p.force > 0.0) || !std::isfinite(p.force))
    msg << "wall servo: the target force must be > 0 N, got " << p.force;
  else if (!(p.max_velocity > 0.0) || !std::isfinite(p.max_velocity))
    msg << "wall servo: the largest velocity must be > 0 m/s, got " << p.max_velocity;
  else if (!(p.gain > 0.0) || !std::isfinite(p.gain))
    msg << "wall servo: the gain must be > 0 m/(s N), got " << p.gain;
  else if (!p.normal.allFinite() || !(p.normal.norm() > 0.0))
    msg << "wall servo: the normal must be finite and not zero";
  if (!msg.str().empty()) throw Error(msg.str());
  p_.normal.normalize();
}

void WallServo::attach(System& system) {
  if (p_.wall < 0 || p_.wall >= system.wall_count())
    throw Error("wall servo: no wall " + std::to_string(p_.wall) + " (the system has " +
                std::to_string(system.wall_count()) + ")");
}

double WallServo::normal_force(const System& system) const {
  return -system.wall_force(p_.wall).dot(p_.normal);
}

void WallServo::end_of_step(System& system, double /*dt*/) {
  const double v =
      std::clamp(p_.gain * (p_.force - normal_force(system)), -p_.max_velocity, p_.max_velocity);
  system.set_wall_velocity(p_.wall, v * p_.normal);
}

}  // namespace partita::dem
