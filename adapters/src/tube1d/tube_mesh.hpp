#pragma once
// The tube's coupling mesh: N + 1 nodes x_i = i L / N on the x axis.

#include "partita/interface/mesh.hpp"
#include "partita/tube1d/tube_parameters.hpp"

namespace partita::adapters {

inline Mesh tube_nodes(const tube1d::TubeParameters& p) {
  Mesh::Points x = Mesh::Points::Zero(p.cells + 1, 3);
  for (int i = 0; i <= p.cells; ++i) x(i, 0) = p.dx() * i;
  return Mesh("nodes", x);
}

}  // namespace partita::adapters
