#include "mesh_locator.hpp"

#include <limits>

#include <Eigen/LU>

#include "partita/fem/shape_functions.hpp"

namespace partita::adapters {

namespace {

bool is_tet(fem::ElementType t) {
  return t == fem::ElementType::Tet4 || t == fem::ElementType::Tet10;
}

// Inside the reference element, with a tolerance: hexahedra [-1, 1]^3, tetrahedra
// xi, eta, zeta >= 0 and xi + eta + zeta <= 1.
bool inside(fem::ElementType t, const fem::Vec3& xi, double tol) {
  if (is_tet(t)) return xi.minCoeff() >= -tol && xi.sum() <= 1.0 + tol;
  return xi.cwiseAbs().maxCoeff() <= 1.0 + tol;
}

// Local coordinates of x in element e by Newton on x(xi) = sum N_i(xi) X_i; false if it does
// not converge or the point lies outside.
bool locate_in(const fem::Mesh& mesh, const fem::Element& e, const fem::Vec3& x, fem::Vec3& xi) {
  fem::ShapeVector n;
  fem::ShapeGradient dn;
  xi = is_tet(e.type) ? fem::Vec3::Constant(0.25) : fem::Vec3::Zero();
  const auto nodes = e.node_span();
  for (int it = 0; it < 30; ++it) {
    fem::shape_functions(e.type, xi, n, dn);
    fem::Vec3 r = -x;
    Eigen::Matrix3d j = Eigen::Matrix3d::Zero();  // dx/dxi
    for (std::size_t a = 0; a < nodes.size(); ++a) {
      const fem::Vec3& xa = mesh.node(nodes[a]);
      r += n(static_cast<Eigen::Index>(a)) * xa;
      j += xa * dn.row(static_cast<Eigen::Index>(a));
    }
    const fem::Vec3 step = j.partialPivLu().solve(r);
    xi -= step;
    if (!xi.allFinite() || xi.cwiseAbs().maxCoeff() > 10.0) return false;
    if (step.norm() < 1e-14) break;
  }
  return inside(e.type, xi, 1e-9);
}

}  // namespace

MeshLocator::MeshLocator(const fem::Mesh& mesh) : mesh_(mesh) {
  boxes_.reserve(mesh.num_elements());
  for (const auto& e : mesh.elements()) {
    fem::Vec3 lo = fem::Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for (const std::size_t k : e.node_span()) {
      lo = lo.cwiseMin(mesh.node(k));
      hi = hi.cwiseMax(mesh.node(k));
    }
    const double pad = 1e-9 * (hi - lo).norm();
    boxes_.emplace_back(lo.array() - pad, hi.array() + pad);
  }
}

std::optional<MeshLocation> MeshLocator::locate(const fem::Vec3& x) const {
  MeshLocation at;
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) {
    const auto& [lo, hi] = boxes_[e];
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
    if (locate_in(mesh_, mesh_.element(e), x, at.xi)) {
      at.element = e;
      return at;
    }
  }
  return std::nullopt;
}

fem::Vec3 MeshLocator::interpolate(const MeshLocation& at, const Eigen::VectorXd& nodal) const {
  const fem::Element& e = mesh_.element(at.element);
  fem::ShapeVector n;
  fem::ShapeGradient dn;
  fem::shape_functions(e.type, at.xi, n, dn);
  const auto nodes = e.node_span();
  fem::Vec3 v = fem::Vec3::Zero();
  for (std::size_t a = 0; a < nodes.size(); ++a)
    v += n(static_cast<Eigen::Index>(a)) * nodal.segment<3>(3 * static_cast<Eigen::Index>(nodes[a]));
  return v;
}

}  // namespace partita::adapters
