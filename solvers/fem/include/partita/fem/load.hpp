#pragma once
#include <string>

#include "partita/fem/types.hpp"

namespace partita::fem {

enum class LoadKind {
  Pressure,    // pressure p [Pa] on face `target`, acting against the outward normal: t = -p n
  Traction,    // traction vector [Pa] on face `target`
  NodalForce,  // force [N] on every node of node set `target`
  Gravity,     // body acceleration [m/s^2] on every element (force density rho g)
};

// A load defined with the model: its magnitude times amplitude(t) (1 when empty).
// The coupling inputs (tractions at quadrature points, nodal forces) are not Loads: they are
// set on the StructuralSolver between steps.
struct Load {
  LoadKind kind = LoadKind::Pressure;
  std::string target;
  double pressure = 0.0;
  Vec3 vector = Vec3::Zero();
  TimeFunction amplitude;
};

}  // namespace partita::fem
