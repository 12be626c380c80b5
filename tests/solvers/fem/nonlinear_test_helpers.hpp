#pragma once
// Shared helpers of the nonlinear FEM tests (not a test file itself).
#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <optional>
#include <regex>
#include <sstream>
#include <string>

#include "fem_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/internal_force_operator.hpp"
#include "partita/fem/model.hpp"
#include "partita/fem/nonlinear_operator.hpp"
#include "partita/fem/newton_report.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem::test {

// Largest relative deviation |K du - (f(u + h du) - f(u - h du)) / 2h| / |K du| over random
// directions du: the tangent against central finite differences of the internal force. Each
// evaluation starts from the committed history, so this checks the algorithmic tangent.
inline double tangent_fd_error(InternalForceOperator& op, const Eigen::VectorXd& u, double h,
                               int directions, unsigned long long seed) {
  Lcg rng(seed);
  Eigen::VectorXd f, fp, fm;
  SparseMatrix k;
  op.evaluate(u, f, &k);
  double worst = 0.0;
  for (int d = 0; d < directions; ++d) {
    Eigen::VectorXd du(u.size());
    for (Eigen::Index i = 0; i < du.size(); ++i) du[i] = rng.next();
    op.evaluate(u + h * du, fp, nullptr);
    op.evaluate(u - h * du, fm, nullptr);
    const Eigen::VectorXd kdu = k * du;
    const Eigen::VectorXd fd = (fp - fm) / (2.0 * h);
    worst = std::max(worst, (kdu - fd).norm() / kdu.norm());
  }
  return worst;
}

// Box (2 x 1 x depth, 2 x 2 x 2 cells of `type`) with its interior nodes moved randomly by up to
// 15 % of a cell, with one law everywhere.
inline Model distorted_box(ElementType type, double depth, std::shared_ptr<const MaterialLaw> law,
                           unsigned long long seed) {
  BoxSpec spec{Vec3::Zero(), Vec3(2.0, 1.0, depth), {2, 2, 2}, type};
  Mesh mesh = make_box_mesh(spec);
  distort_interior(mesh, spec, 0.15, seed);
  Model m(std::move(mesh));
  m.set_material_law(std::move(law));
  return m;
}

// u = (F0 - I) X + a random perturbation of 0.01: a large, non-symmetric, non-homogeneous
// deformation (F0 = [1.3 0.2 0; 0 0.9 0.1; 0.05 0 1.1]).
inline Eigen::VectorXd large_deformation(const Mesh& mesh, unsigned long long seed) {
  Mat3 f0;
  f0 << 1.3, 0.2, 0.0, 0.0, 0.9, 0.1, 0.05, 0.0, 1.1;
  Lcg rng(seed);
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(mesh.num_nodes()));
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n) {
    u.segment<3>(3 * static_cast<Eigen::Index>(n)) =
        (f0 - Mat3::Identity()) * mesh.node(n) + 0.01 * Vec3(rng.next(), rng.next(), rng.next());
  }
  return u;
}

// Pairs (r_k, r_k+1) of relative residuals with lo < r_k < 1e-2 (the asymptotic range, above
// the accuracy floor lo) that violate quadratic convergence r_k+1 <= 10 r_k^2, and how many
// pairs were checked.
struct QuadraticCheck {
  int checked = 0;
  int violations = 0;
};
inline QuadraticCheck check_quadratic(const NewtonReport& rep, double lo) {
  QuadraticCheck c;
  const auto& r = rep.residual_norms;
  for (std::size_t k = 0; k + 1 < r.size(); ++k) {
    const double a = r[k] / rep.reference_force, b = r[k + 1] / rep.reference_force;
    if (a < 1e-2 && a > lo) {
      ++c.checked;
      if (!(b <= 10.0 * a * a)) ++c.violations;
    }
  }
  return c;
}

// Cantilever 10 x 1 x 1 (10 x 2 x 2 Hex20) of `law`, clamped at x = 0, its end x = 10 pushed
// down by `tip` in `steps` load steps: the Newton report of the last step, the largest
// equivalent plastic strain and the relative residual sequence as text.
struct BendingRun {
  NewtonReport report;
  double max_plastic_strain = 0.0;
  std::string residuals;
};
inline BendingRun plastic_bending(std::shared_ptr<const MaterialLaw> law, double tip,
                                  double force_tolerance, int steps) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(10.0, 1.0, 1.0), {10, 2, 2}, ElementType::Hex20}));
  m.set_material_law(std::move(law));
  m.fix("xmin");
  m.prescribe("xmax", 2, [tip](double t) { return -tip * t; });
  SolverOptions opt;
  opt.newton.force_tolerance = force_tolerance;
  opt.newton.load_steps = steps;
  StructuralSolver s(std::move(m), opt);
  s.step_static(1.0);
  BendingRun run{s.static_reports().back(), s.equivalent_plastic_strain().maxCoeff(), ""};
  std::ostringstream seq;
  for (double r : run.report.residual_norms) seq << r / run.report.reference_force << " ";
  run.residuals = seq.str();
  return run;
}

// Root of a monotone scalar function on [lo, hi] by bisection to round-off.
inline double bisect(const std::function<double(double)>& g, double lo, double hi) {
  double glo = g(lo);
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    const double gm = g(mid);
    if ((gm > 0) == (glo > 0)) {
      lo = mid;
      glo = gm;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

// Mean z-displacement of the face "xmax", positive downwards (a cantilever's tip deflection
// under a load in -z).
inline double tip_deflection(const StructuralSolver& s) {
  double w = 0.0;
  const auto& nodes = s.mesh().node_set("xmax");
  for (auto n : nodes) w += s.displacement(n).z();
  return -w / static_cast<double>(nodes.size());
}

// step_static(1.0) of a load beyond a limit load: the largest load factor reached (or carried,
// where the displacement ran away under converged increments), read from the
// limit-load message; nullopt when it converged or failed otherwise. `what` gets the message.
inline std::optional<double> limit_load_factor(StructuralSolver& s, std::string& what) {
  what.clear();
  try {
    s.step_static(1.0);
  } catch (const Error& e) {
    what = e.what();
  }
  std::smatch m;
  if (what.find("limit load") == std::string::npos ||
      !std::regex_search(what, m, std::regex("largest load factor (?:reached|carried) is ([0-9.eE+-]+)")))
    return std::nullopt;
  return std::stod(m[1].str());
}

// Patch test of a model's operator: u = (F0 - I) X gives every quadrature point the law's
// stress at F0 (to 1e-10) and leaves the interior nodes (those of 8 elements) in equilibrium
// (to 1e-9 of |f|).
inline void check_homogeneous_patch(const Model& m, const Mat3& f0, const MaterialLaw& law) {
  NonlinearOperator op(m);
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(m.mesh().num_nodes())), f;
  for (std::size_t n = 0; n < m.mesh().num_nodes(); ++n)
    u.segment<3>(3 * static_cast<Eigen::Index>(n)) = (f0 - Mat3::Identity()) * m.mesh().node(n);
  op.evaluate(u, f, nullptr);
  std::vector<double> none(static_cast<std::size_t>(law.state_size())), trial(none.size());
  law.initialise_state(none);
  MaterialResponse r;
  law.evaluate(f0, none, trial, r);
  const Mat3 sigma =
      law.small_strain() ? r.stress : Mat3(r.stress * f0.transpose() / f0.determinant());
  Eigen::Matrix<double, 1, 6> exact;
  exact << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2), sigma(0, 2);
  for (Eigen::Index q = 0; q < op.cauchy_stress().rows(); ++q)
    CHECK((op.cauchy_stress().row(q) - exact).norm() < 1e-10 * exact.norm());
  std::vector<int> count(m.mesh().num_nodes(), 0);
  for (const auto& e : m.mesh().elements())
    for (auto n : e.node_span()) ++count[n];
  for (std::size_t n = 0; n < m.mesh().num_nodes(); ++n)
    if (count[n] == 8) CHECK(f.segment<3>(3 * static_cast<Eigen::Index>(n)).norm() < 1e-9 * f.norm());
}

}  // namespace partita::fem::test
