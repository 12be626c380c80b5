#pragma once
// The farthest a particle can be from its position at the last list build after the next first
// half (VelocityVerlet: x += dt (v + dt/2 F/m)), from the last step's motion: what lets a step
// rule out a list build before it moves anything (System::step()'s fused pass, and a split bed's,
// System::phase_fusable()). Rounding: relative in the sums, absolute in x += dt v and x - x_build.

#include "partita/dem/velocity_verlet.hpp"

#include <limits>

namespace partita::dem::detail {

inline double motion_bound(const VelocityVerlet::Motion& mo, double dt) {
  const double drift = dt * (mo.speed + 0.5 * dt * mo.accel);
  const double eps = std::numeric_limits<double>::epsilon();
  return (mo.moved + drift) * (1.0 + 1e-12) + 8.0 * eps * (mo.extent + drift);
}

}  // namespace partita::dem::detail
