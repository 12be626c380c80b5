#pragma once
// Grading (particle size distribution) of a particle set: the cumulative mass fraction passing
// each size, as a sieve analysis reports it.

#include "partita/dem/particles.hpp"

#include <vector>

namespace partita::dem {

class Grading {
 public:
  struct Point {
    double size;     ///< diameter d [m]
    double passing;  ///< mass of the particles with diameter <= d over the total mass [-]
  };
  /// One point per distinct diameter, ascending (the last passes 1); empty without particles.
  static std::vector<Point> cumulative(const Particles& particles);
  /// The fraction passing each of the given sizes [m].
  static std::vector<double> passing(const Particles& particles, const std::vector<double>& sizes);
};

}  // namespace partita::dem
