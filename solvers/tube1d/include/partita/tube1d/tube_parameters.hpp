#pragma once
// Parameters of the 1D elastic tube (defaults: the preCICE tutorial elastic-tube-1d after
// Degroote et al., Comput. Struct. 86 (2008)). Nodes x_i = i L / N, i = 0..N.

#include <cmath>
#include <numbers>

namespace partita::tube1d {

struct TubeParameters {
  int cells = 100;                                    ///< N
  double length = 10.0;                               ///< L [m]
  double youngs_modulus = 10000.0;                    ///< E [Pa]
  double radius = 1.0 / std::sqrt(std::numbers::pi);  ///< r0 [m] (a0 = pi r0^2 = 1)
  double reference_area = 1.0;                        ///< a0 [m^2], the area at p = p0
  double reference_pressure = 0.0;                    ///< p0 [Pa]
  double density = 1.0;                               ///< rho [kg/m^3]
  double inlet_velocity = 10.0;                       ///< mean inlet velocity u_in [m/s]
  double inlet_amplitude = 3.0;                       ///< amplitude of the inlet velocity [m/s]
  double inlet_frequency = 5.0;    ///< f [Hz]: u_in(t) = u_in + A sin(2 pi f t) (10 pi t for 5 Hz)
  double initial_velocity = 10.0;  ///< u(0) [m/s]
  double initial_pressure = 0.0;   ///< p(0) [Pa]

  /// Squared wave speed c^2 = E / (2 rho r0) [m^2/s^2].
  double wave_speed_squared() const { return youngs_modulus / (2.0 * density * radius); }
  double dx() const { return length / cells; }
  /// u_in(t) = u_in + A sin(2 pi f t)
  double inlet(double t) const {
    return inlet_velocity +
           inlet_amplitude * std::sin(2.0 * std::numbers::pi * inlet_frequency * t);
  }
};

}  // namespace partita::tube1d
