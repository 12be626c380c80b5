#pragma once
// A line probe of an FE model: N points evenly along a segment, each located once in the
// reference mesh (its element and local coordinates), then sampled at every output time:
// displacement u(x) = sum_i N_i(xi) u_i, Cauchy stress by the same interpolation of the nodal
// (element-averaged) stresses, von Mises of that stress, the equivalent plastic strain of the
// element that holds the point (the mean of its quadrature points: constant per element). Written as one CSV per output time:
// s [m] (the distance along the segment), x, y, z [m], then the fields.

#include <filesystem>
#include <string>
#include <vector>

#include "partita/fem/fem.hpp"

namespace partita::adapters {

class LineProbe {
 public:
  enum class Field { displacement, stress, von_mises, equivalent_plastic_strain };

  /// Locates `points` >= 2 points from `from` to `to` in `mesh`; throws fem::Error naming the
  /// first point that lies in no element (the segment leaves the model).
  LineProbe(std::string name, const fem::Mesh& mesh, const fem::Vec3& from, const fem::Vec3& to,
            int points, std::vector<Field> fields);

  const std::string& name() const { return name_; }
  /// The CSV text for the solver's current state.
  std::string csv(const fem::StructuralSolver& solver) const;

 private:
  struct Point {
    fem::Vec3 x;
    double s = 0.0;
    std::size_t element = 0;
    fem::Vec3 xi;
  };
  std::string name_;
  const fem::Mesh* mesh_;
  std::vector<Point> points_;
  std::vector<Field> fields_;
};

}  // namespace partita::adapters
