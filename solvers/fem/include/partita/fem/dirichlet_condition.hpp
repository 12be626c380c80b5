#pragma once
#include <string>

#include "partita/fem/types.hpp"

namespace partita::fem {

// u_component = value(X, t) on every node of node_set (X: reference position). An empty value
// means fixed (u = 0). Later conditions on the same dof replace earlier ones.
struct DirichletCondition {
  std::string node_set;
  int component = 0;  // 0 = x, 1 = y, 2 = z
  SpaceTimeFunction value;
};

}  // namespace partita::fem
