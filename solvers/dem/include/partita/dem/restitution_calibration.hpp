#pragma once
// The damping ratio that makes a damped Hertz contact rebound with a given restitution.
//
// Normal contact with viscous damping gamma = 2 zeta sqrt(S_n m*), S_n = 2 E* sqrt(R* delta):
//   m* delta'' = -4/3 E* sqrt(R*) delta^(3/2) - gamma delta'
// Scaling delta = D x and t = T tau with T^2 = m*/(4/3 E* sqrt(R*) D^(1/2)) and D = v0 T turns it
// into the parameter-free equation
//   x'' = -x^(3/2) - 2 sqrt(3/2) zeta x^(1/4) x',   x(0) = 0, x'(0) = 1,
// so the realised restitution e = -x'(end) depends on zeta only, not on the impact speed, the
// masses or the stiffness (Antypov & Elliott, EPL 94 (2011) 50004; Thornton, Cummins & Cleary,
// Powder Technol. 233 (2013) 30-46). The linear-spring expression zeta = -ln(e)/sqrt(ln(e)^2+pi^2)
// (times sqrt(5/6) in LIGGGHTS) is therefore not exact for Hertz contacts: we integrate the scaled
// equation numerically (RK4) and invert e(zeta) by bisection, once per interaction.

namespace partita::dem {

class RestitutionCalibration {
 public:
  /// Realised restitution of the damped Hertz contact with damping ratio zeta >= 0.
  /// no_tension: the normal force is clamped at zero (no attraction at the end of the contact).
  static double restitution(double zeta, bool no_tension);
  /// The damping ratio zeta whose realised restitution is e (0 < e <= 1). Throws Error outside.
  static double damping_ratio(double e, bool no_tension = true);
  /// LIGGGHTS/EDEM damping ratio: zeta = -sqrt(5/6) ln(e)/sqrt(ln(e)^2 + pi^2).
  static double liggghts_damping_ratio(double e);
  /// Fraction of the Rayleigh step at which velocity Verlet realises the calibrated e to 1 % for
  /// sphere-sphere and sphere-wall impacts from 0.01 to 10 m/s (up to 1.6 % of the wave speed
  /// sqrt(E/rho)). The damping force uses the half-step velocity, an error of first order in
  /// dt that grows with the damping: measured at 0.2 of the Rayleigh step over 0.01..10 m/s,
  /// e = 0.1 is realised 2.2 % low and e = 0.3..0.7 up to 2.5 % off
  /// (tests/solvers/dem/test_time_step_fraction.cpp). Piecewise constant in e (0 < e <= 1): 0.02 below
  /// e = 0.15, 0.05 below 0.2, 0.1 below 0.9, else 0.2. A second-order damping velocity does not
  /// help: at 10 m/s a contact of these spheres lasts 3.4 steps of 0.2 dt_R, and damping on the
  /// end-of-step velocity (v_{n+1/2} + dt/2 F/m*, solved per contact in closed form) realised
  /// e = 0.1 18.7 % high and e = 0.3 7.7 % high at 0.2 (the half-step velocity's errors partly
  /// cancel those of the contact's start and end, which fall between steps); with the
  /// half-step velocity e = 0.1 still comes out 1.0 % low at 0.025 (at 10 m/s): the error there is
  /// of the contact's start (damping ~ delta^(1/4), steep at touch), not of the damping lag.
  static double time_step_fraction(double e);
};

}  // namespace partita::dem
