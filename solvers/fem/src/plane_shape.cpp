#include "partita/fem/plane_shape.hpp"

#include "partita/fem/error.hpp"

namespace partita::fem {

PlaneShape::PlaneShape(const Vec3& point, const Vec3& normal) : point_(point) {
  if (!(normal.norm() > 0.0) || !normal.allFinite() || !point.allFinite())
    throw Error("plane: the normal must be a non-zero vector and the point finite");
  normal_ = normal.normalized();
}

}  // namespace partita::fem
