#pragma once
#include <vector>

#include "partita/fem/types.hpp"

namespace partita::fem {

// A prescribed velocity v(t) [m/s], piecewise linear between the rows (t_i, v_i), held constant
// before the first and after the last row; its exact integral gives the displacement, so a
// driven indenter lands on the same position whatever the step size.
class VelocityTable {
 public:
  // Throws Error for no rows, non-increasing times or non-finite values.
  explicit VelocityTable(std::vector<std::pair<double, Vec3>> rows);
  Vec3 velocity(double t) const;
  // int_0^t v(s) ds
  Vec3 displacement(double t) const;

 private:
  Vec3 integral_from_first(double t) const;  // int_{t_0}^t v ds (negative before t_0)
  std::vector<std::pair<double, Vec3>> rows_;
  std::vector<Vec3> cumulative_;  // int_{t_0}^{t_i} v ds
};

}  // namespace partita::fem
