#include "partita/fem/triangulated_shape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "partita/fem/error.hpp"
#include "partita/geometry/closest_point.hpp"

namespace partita::fem {

TriangulatedShape::TriangulatedShape(std::vector<Vec3> vertices,
                                     std::vector<std::array<int, 3>> triangles,
                                     double search_radius)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)), search_radius_(search_radius) {
  if (vertices_.empty() || triangles_.empty())
    throw Error("triangulated surface: no vertices or no triangles");
  if (!(search_radius > 0.0) || !std::isfinite(search_radius))
    throw Error("triangulated surface: the search radius must be > 0, got " +
                std::to_string(search_radius));
  const int nv = static_cast<int>(vertices_.size());
  vertex_normal_.assign(vertices_.size(), Vec3::Zero());
  std::map<std::pair<int, int>, Vec3> edge_sum;  // sum of the two adjacent face normals
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= nv)
        throw Error("triangulated surface: triangle " + std::to_string(t) + " refers to vertex " +
                    std::to_string(tri[k]) + "; there are " + std::to_string(nv));
    const Vec3 n = (vertices_[tri[1]] - vertices_[tri[0]]).cross(vertices_[tri[2]] - vertices_[tri[0]]);
    if (!(n.norm() > 0.0))
      throw Error("triangulated surface: triangle " + std::to_string(t) + " is degenerate (zero area)");
    face_normal_.push_back(n.normalized());
    for (int k = 0; k < 3; ++k) {
      // angle-weighted vertex pseudo-normal: sum of the incident faces' normals times their
      // angles at the vertex
      const Vec3 e1 = (vertices_[tri[(k + 1) % 3]] - vertices_[tri[k]]).normalized();
      const Vec3 e2 = (vertices_[tri[(k + 2) % 3]] - vertices_[tri[k]]).normalized();
      vertex_normal_[tri[k]] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * face_normal_.back();
      edge_sum.try_emplace(std::minmax(tri[k], tri[(k + 1) % 3]), Vec3::Zero())
          .first->second += face_normal_.back();
    }
  }
  edge_normal_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k)
      edge_normal_[t][k] = edge_sum.at(std::minmax(triangles_[t][k], triangles_[t][(k + 1) % 3]));

  // the grid: cells of edge >= search radius over the bounding box grown by it
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& v : vertices_) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  lo_ = lo - Vec3::Constant(search_radius_);
  const Vec3 extent = hi - lo + Vec3::Constant(2.0 * search_radius_);
  cell_size_ = std::max(search_radius_, extent.maxCoeff() / 64.0);
  for (int d = 0; d < 3; ++d)
    dims_[d] = std::max<long>(1, static_cast<long>(std::ceil(extent[d] / cell_size_)));
  const auto ncell = static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]);
  auto range = [&](const Vec3& a, const Vec3& b, std::array<long, 3>& i0, std::array<long, 3>& i1) {
    for (int d = 0; d < 3; ++d) {
      i0[d] = std::clamp(static_cast<long>(std::floor((a[d] - lo_[d]) / cell_size_)), 0L, dims_[d] - 1);
      i1[d] = std::clamp(static_cast<long>(std::floor((b[d] - lo_[d]) / cell_size_)), 0L, dims_[d] - 1);
    }
  };
  // two passes: count, then fill (CSR)
  std::vector<std::size_t> count(ncell + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      for (std::size_t c = 0; c < ncell; ++c) count[c + 1] += count[c];
      cell_start_ = count;
      cells_.assign(count[ncell], 0);
    }
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      Vec3 a = vertices_[triangles_[t][0]], b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(vertices_[triangles_[t][k]]);
        b = b.cwiseMax(vertices_[triangles_[t][k]]);
      }
      std::array<long, 3> i0{}, i1{};
      range(a - Vec3::Constant(search_radius_), b + Vec3::Constant(search_radius_), i0, i1);
      for (long i = i0[0]; i <= i1[0]; ++i)
        for (long j = i0[1]; j <= i1[1]; ++j)
          for (long k = i0[2]; k <= i1[2]; ++k) {
            const auto c = static_cast<std::size_t>((k * dims_[1] + j) * dims_[0] + i);
            if (pass == 0)
              ++count[c + 1];
            else
              cells_[count[c]++] = static_cast<int>(t);
          }
    }
  }
}

bool TriangulatedShape::cell_of(const Vec3& x, std::size_t& cell) const {
  std::array<long, 3> i{};
  for (int d = 0; d < 3; ++d) {
    const double s = (x[d] - lo_[d]) / cell_size_;
    if (!(s >= 0.0) || s >= static_cast<double>(dims_[d])) return false;
    i[d] = static_cast<long>(s);
  }
  cell = static_cast<std::size_t>((i[2] * dims_[1] + i[1]) * dims_[0] + i[0]);
  return true;
}

std::size_t TriangulatedShape::max_cell_triangles() const {
  std::size_t m = 0;
  for (std::size_t c = 0; c + 1 < cell_start_.size(); ++c)
    m = std::max(m, cell_start_[c + 1] - cell_start_[c]);
  return m;
}

ShapeDistance TriangulatedShape::distance(const Vec3& x) const {
  const ShapeDistance far{search_radius_, Vec3::UnitZ()};
  std::size_t cell = 0;
  if (!cell_of(x, cell)) return far;
  // nearest triangle among the cell's: every triangle within the search radius of x is listed
  double best = std::numeric_limits<double>::infinity();
  Vec3 closest = Vec3::Zero(), pseudo = Vec3::UnitZ();
  int best_t = -1;
  for (std::size_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
    const int t = cells_[k];
    const auto& tri = triangles_[static_cast<std::size_t>(t)];
    const geometry::TriangleClosestPoint c =
        geometry::closest_point_on_triangle(x, vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]);
    const double d2 = (x - c.point).squaredNorm();
    if (d2 < best) {
      best = d2;
      closest = c.point;
      best_t = t;
      const auto tt = static_cast<std::size_t>(t);
      // the pseudo-normal of the feature: vertex k, edge k (ab, bc, ca) or the face
      pseudo = c.feature == c.vertex ? vertex_normal_[tri[c.local_index]]
               : c.feature == c.edge ? edge_normal_[tt][c.local_index]
                                     : face_normal_[tt];
    }
  }
  const double d = std::sqrt(best);
  if (best_t < 0 || !(d < search_radius_)) return far;
  // sign from the pseudo-normal; outward normal along x - closest (the face's on the surface)
  const Vec3 r = x - closest;
  const double sign = r.dot(pseudo) >= 0.0 ? 1.0 : -1.0;
  const Vec3 n = d > 1e-12 * cell_size_ ? Vec3(sign * r / d) : face_normal_[static_cast<std::size_t>(best_t)];
  return {sign * d, n};
}

}  // namespace partita::fem
