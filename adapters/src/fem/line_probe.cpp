#include "line_probe.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "partita/fem/error.hpp"
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
bool locate(const fem::Mesh& mesh, const fem::Element& e, const fem::Vec3& x, fem::Vec3& xi) {
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

void append(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

}  // namespace

LineProbe::LineProbe(std::string name, const fem::Mesh& mesh, const fem::Vec3& from,
                     const fem::Vec3& to, int points, std::vector<Field> fields)
    : name_(std::move(name)), mesh_(&mesh), fields_(std::move(fields)) {
  if (points < 2) throw fem::Error("line probe '" + name_ + "': at least 2 points are needed");
  // element bounding boxes for a cheap first test
  std::vector<std::pair<fem::Vec3, fem::Vec3>> boxes;
  boxes.reserve(mesh.num_elements());
  for (const auto& e : mesh.elements()) {
    fem::Vec3 lo = fem::Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for (const std::size_t k : e.node_span()) {
      lo = lo.cwiseMin(mesh.node(k));
      hi = hi.cwiseMax(mesh.node(k));
    }
    const double pad = 1e-9 * (hi - lo).norm();
    boxes.emplace_back(lo.array() - pad, hi.array() + pad);
  }
  const double length = (to - from).norm();
  for (int p = 0; p < points; ++p) {
    Point pt;
    const double f = static_cast<double>(p) / static_cast<double>(points - 1);
    pt.x = from + f * (to - from);
    pt.s = f * length;
    bool found = false;
    for (std::size_t e = 0; e < mesh.num_elements() && !found; ++e) {
      const auto& [lo, hi] = boxes[e];
      if ((pt.x.array() < lo.array()).any() || (pt.x.array() > hi.array()).any()) continue;
      if (locate(mesh, mesh.element(e), pt.x, pt.xi)) {
        pt.element = e;
        found = true;
      }
    }
    if (!found)
      throw fem::Error("line probe '" + name_ + "': point " + std::to_string(p) + " at (" +
                       std::to_string(pt.x.x()) + ", " + std::to_string(pt.x.y()) + ", " +
                       std::to_string(pt.x.z()) +
                       ") lies in no element: the segment leaves the model");
    points_.push_back(pt);
  }
}

std::string LineProbe::csv(const fem::StructuralSolver& solver) const {
  const bool want_stress =
      std::any_of(fields_.begin(), fields_.end(), [](Field f) { return f != Field::displacement; });
  const fem::MatrixX6 stress = want_stress ? solver.nodal_stress() : fem::MatrixX6();
  const Eigen::VectorXd& u = solver.displacement();
  std::string s = "s [m],x [m],y [m],z [m]";
  const char* voigt[] = {"xx", "yy", "zz", "xy", "yz", "zx"};  // the FEM's Voigt order
  for (Field f : fields_) {
    if (f == Field::displacement) s += ",displacement_x [m],displacement_y [m],displacement_z [m]";
    if (f == Field::stress)
      for (const char* c : voigt) s += std::string(",stress_") + c + " [Pa]";
    if (f == Field::von_mises) s += ",von_mises [Pa]";
  }
  s += "\n";
  fem::ShapeVector n;
  fem::ShapeGradient dn;
  for (const Point& p : points_) {
    const fem::Element& e = mesh_->element(p.element);
    fem::shape_functions(e.type, p.xi, n, dn);
    const auto nodes = e.node_span();
    fem::Vec3 up = fem::Vec3::Zero();
    Eigen::Matrix<double, 1, 6> sp = Eigen::Matrix<double, 1, 6>::Zero();
    for (std::size_t a = 0; a < nodes.size(); ++a) {
      const double w = n(static_cast<Eigen::Index>(a));
      up += w * u.segment<3>(3 * static_cast<Eigen::Index>(nodes[a]));
      if (want_stress) sp += w * stress.row(static_cast<Eigen::Index>(nodes[a]));
    }
    append(s, p.s);
    for (int k = 0; k < 3; ++k) s += ",", append(s, p.x(k));
    for (Field f : fields_) {
      if (f == Field::displacement)
        for (int k = 0; k < 3; ++k) s += ",", append(s, up(k));
      if (f == Field::stress)
        for (int k = 0; k < 6; ++k) s += ",", append(s, sp(k));
      if (f == Field::von_mises) {
        fem::MatrixX6 one(1, 6);
        one.row(0) = sp;
        s += ",", append(s, fem::StructuralSolver::von_mises(one)(0));
      }
    }
    s += "\n";
  }
  return s;
}

}  // namespace partita::adapters
