#pragma once
#include <cstddef>
#include <string>

#include "partita/fem/types.hpp"

namespace partita::fem {

// An element that reached its failure strain (StructuralSolver::first_failure()).
struct FailureEvent {
  std::size_t element = 0;
  std::string region;                // its region's name (the part)
  Vec3 centroid = Vec3::Zero();      // mean of its nodes, reference configuration [m]
  double time = 0.0;                 // end of the step in which it failed [s]
  double plastic_strain = 0.0;       // its mean equivalent plastic strain then
  double failure_strain = 0.0;       // its eps_f (RTCL: eps_cr; BWH: eps_3)
  double damage = -1.0;              // RTCL, BWH: its mean damage then (>= 1); else -1
};

}  // namespace partita::fem
