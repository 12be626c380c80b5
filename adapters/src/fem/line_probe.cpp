#include "line_probe.hpp"

#include "mesh_locator.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "partita/fem/error.hpp"
#include "partita/fem/shape_functions.hpp"

namespace partita::adapters {

namespace {

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
  const MeshLocator locator(mesh);
  const double length = (to - from).norm();
  for (int p = 0; p < points; ++p) {
    Point pt;
    const double f = static_cast<double>(p) / static_cast<double>(points - 1);
    pt.x = from + f * (to - from);
    pt.s = f * length;
    const auto at = locator.locate(pt.x);
    const bool found = at.has_value();
    if (found) {
      pt.element = at->element;
      pt.xi = at->xi;
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
  const bool want_stress = std::any_of(fields_.begin(), fields_.end(), [](Field f) {
    return f == Field::stress || f == Field::von_mises;
  });
  const bool want_eqps = std::find(fields_.begin(), fields_.end(),
                                   Field::equivalent_plastic_strain) != fields_.end();
  Eigen::VectorXd eqps = want_eqps ? solver.element_equivalent_plastic_strain() : Eigen::VectorXd();
  if (want_eqps && eqps.size() == 0)  // linear elastic: no plastic strain anywhere
    eqps = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh_->num_elements()));
  const fem::MatrixX6 stress = want_stress ? solver.nodal_stress() : fem::MatrixX6();
  const Eigen::VectorXd& u = solver.displacement();
  std::string s = "s [m],x [m],y [m],z [m]";
  const char* voigt[] = {"xx", "yy", "zz", "xy", "yz", "zx"};  // the FEM's Voigt order
  for (Field f : fields_) {
    if (f == Field::displacement) s += ",displacement_x [m],displacement_y [m],displacement_z [m]";
    if (f == Field::stress)
      for (const char* c : voigt) s += std::string(",stress_") + c + " [Pa]";
    if (f == Field::von_mises) s += ",von_mises [Pa]";
    if (f == Field::equivalent_plastic_strain) s += ",equivalent_plastic_strain";
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
      if (f == Field::equivalent_plastic_strain)
        s += ",", append(s, eqps[static_cast<Eigen::Index>(p.element)]);
    }
    s += "\n";
  }
  return s;
}

}  // namespace partita::adapters
