#include "partita/coupling/mapping/rbf_mapper.hpp"

#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "local_frame.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "point_tree.hpp"

namespace partita::coupling {

namespace {

const char* basis_name(RbfMapper::Basis b) {
  switch (b) {
    case RbfMapper::Basis::wendland_c2:
      return "wendland-c2";
    case RbfMapper::Basis::gaussian:
      return "gaussian";
    case RbfMapper::Basis::thin_plate_spline:
      return "thin-plate-spline";
  }
  return "?";
}

}  // namespace

/// The factorised interpolation system and the evaluation operators of one compute().
struct RbfMapper::System {
  using SparseCol = Eigen::SparseMatrix<double>;
  using SparseRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  Eigen::Index n = 0;  ///< centres
  int q = 0;           ///< polynomial terms (0: off)
  bool dense = false;

  SparseRow eval;                         ///< E = Phi(evaluation points, centres), compact basis
  Eigen::MatrixXd eval_dense;             ///< E, global basis
  Eigen::MatrixXd poly_centres;           ///< P_C, n x q
  Eigen::MatrixXd poly_eval;              ///< P_X, n_eval x q
  Eigen::MatrixXd pinv;                   ///< (P_C^T P_C)^-1 P_C^T, q x n (separate)
  Eigen::SimplicialLDLT<SparseCol> ldlt;  ///< Phi, compact basis (cholesky)
  SparseCol phi;                          ///< Phi, lower triangle (cg keeps a reference)
  Eigen::ConjugateGradient<SparseCol, Eigen::Lower, Eigen::IncompleteCholesky<double>> cg;
  bool iterative = false;
  Eigen::PartialPivLU<Eigen::MatrixXd> dense_lu;  ///< Phi or [Phi P; P^T 0], global basis
  Eigen::MatrixXd phi_inv_p;                      ///< Y = Phi^-1 P_C, n x q (on, compact)
  Eigen::LDLT<Eigen::MatrixXd> schur;             ///< S = P_C^T Phi^-1 P_C, q x q (on, compact)

  /// Phi^-1 rhs (global basis with `on`: K^-1 rhs with K = [Phi P; P^T 0]); symmetric.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const {
    if (dense) return dense_lu.solve(rhs);
    if (!iterative) return ldlt.solve(rhs);
    Eigen::MatrixXd x = cg.solve(rhs);
    if (cg.info() != Eigen::Success)
      throw Error("mapper 'rbf': conjugate gradients did not reach the tolerance in " +
                  std::to_string(cg.iterations()) + " iterations (relative residual " +
                  std::to_string(cg.error()) + "); use solver: cholesky");
    return x;
  }
  /// [alpha; c] = K^-1 [f; g] for K = [Phi P_C; P_C^T 0] (on). Compact basis: through the
  /// Schur complement, keeping the sparse Cholesky factor of Phi:
  ///   c = S^-1 (Y^T f - g),  alpha = Phi^-1 f - Y c.
  void solve_saddle(const Eigen::MatrixXd& f, const Eigen::MatrixXd& g, Eigen::MatrixXd& alpha,
                    Eigen::MatrixXd& c) const {
    if (dense) {
      Eigen::MatrixXd rhs(n + q, f.cols());
      rhs.topRows(n) = f;
      rhs.bottomRows(q) = g;
      const Eigen::MatrixXd z = dense_lu.solve(rhs);
      alpha = z.topRows(n);
      c = z.bottomRows(q);
      return;
    }
    alpha = solve(f);
    c = schur.solve(phi_inv_p.transpose() * f - g);
    alpha.noalias() -= phi_inv_p * c;
  }
  /// E a.
  Eigen::MatrixXd apply_eval(const Eigen::MatrixXd& a) const {
    if (dense) return eval_dense * a;
    return eval * a;
  }
  /// E^T g.
  Eigen::MatrixXd apply_eval_transposed(const Eigen::MatrixXd& g) const {
    if (dense) return eval_dense.transpose() * g;
    return eval.transpose() * g;
  }
};

RbfMapper::RbfMapper(Constraint constraint, Basis basis, double support_radius,
                     Polynomial polynomial, Solver solver, double tolerance)
    : constraint_(constraint),
      basis_(basis),
      radius_(support_radius),
      polynomial_(polynomial),
      solver_(solver),
      tolerance_(tolerance) {
  if (basis_ != Basis::thin_plate_spline && !(radius_ > 0.0 && std::isfinite(radius_)))
    throw Error("mapper 'rbf' with basis " + std::string(basis_name(basis_)) +
                ": support_radius must be a positive length, found " + std::to_string(radius_) +
                "; choose about 3 to 5 mesh spacings");
  if (polynomial_ == Polynomial::off && constraint_ == Constraint::conservative)
    throw Error(
        "mapper 'rbf' with polynomial: off does not reproduce constants, so a conservative "
        "mapping would not preserve the total; use polynomial: separate or on");
  if (polynomial_ == Polynomial::off && basis_ == Basis::thin_plate_spline)
    throw Error(
        "mapper 'rbf' with basis thin-plate-spline needs the linear polynomial; use polynomial: "
        "on");
}

RbfMapper::~RbfMapper() = default;

int RbfMapper::polynomial_terms() const {
  return system_ ? system_->q : 0;
}

std::shared_ptr<const config::Spec> RbfMapper::spec() {
  auto s = std::make_shared<config::Spec>("rbf",
                                          "Radial basis functions with a linear polynomial "
                                          "(compact Wendland C2: sparse factorisation)");
  s->string("type", "the mapper's name, when the mapper is given as a map");
  s->choice("basis",
            "radial basis: compact wendland-c2, or global (dense, small meshes) gaussian, "
            "thin-plate-spline",
            {"wendland-c2", "gaussian", "thin-plate-spline"})
      .def("wendland-c2");
  s->real("support_radius",
          "support radius R of wendland-c2 (about 3-5 mesh spacings); length scale of gaussian")
      .unit("m")
      .positive();
  s->choice("polynomial",
            "linear polynomial: separate (fitted first), on (saddle-point system), off",
            {"separate", "on", "off"})
      .def("separate");
  s->choice("solver",
            "compact system: cholesky (sparse factorisation), cg (conjugate gradients, large "
            "meshes) or auto (cholesky up to 20000 points, cg above)",
            {"auto", "cholesky", "cg"})
      .def("auto");
  s->real("tolerance", "relative residual at which cg stops").positive().def(1e-10);
  return s;
}

std::unique_ptr<Mapper> RbfMapper::create(const MapperContext& context) {
  const config::Node& node = context.config;
  if (!node.is_map())
    node.fail(
        "mapper 'rbf' needs its support radius; write it as a map, e.g. {type: rbf, "
        "support_radius: 2.0e-3} "
        "(a length of about 3 to 5 mesh spacings)");
  const config::Node o = mapper_options(node, spec());
  const std::string b = o.string("basis");
  const Basis basis = b == "gaussian"            ? Basis::gaussian
                      : b == "thin-plate-spline" ? Basis::thin_plate_spline
                                                 : Basis::wendland_c2;
  const std::string p = o.string("polynomial");
  const Polynomial poly = p == "on"    ? Polynomial::on
                          : p == "off" ? Polynomial::off
                                       : Polynomial::separate;
  double radius = 0.0;
  if (basis != Basis::thin_plate_spline) {
    if (!o.has("support_radius"))
      node.fail("mapper 'rbf' with basis " + b +
                " needs support_radius (a length of about 3 to 5 mesh spacings), e.g. {type: rbf, "
                "support_radius: 2.0e-3}");
    radius = o.real("support_radius");
  }
  try {
    const std::string sv = o.string("solver");
    const Solver solver = sv == "cg"         ? Solver::cg
                          : sv == "cholesky" ? Solver::cholesky
                                             : Solver::automatic;
    return std::make_unique<RbfMapper>(context.constraint, basis, radius, poly, solver,
                                       o.real("tolerance"));
  } catch (const Error& e) {
    node.fail(e.what());
  }
}

void RbfMapper::compute(const Mesh& from, const Mesh& to) {
  const Mesh& centres = constraint_ == Constraint::consistent ? from : to;
  const Mesh& points = constraint_ == Constraint::consistent ? to : from;
  if (from.size() == 0 || to.size() == 0)
    throw Error("mapper 'rbf' from mesh '" + from.name() + "' to mesh '" + to.name() + "': mesh '" +
                (from.size() == 0 ? from.name() : to.name()) + "' has no points");
  const bool dense = basis_ != Basis::wendland_c2;
  if (dense && std::max(from.size(), to.size()) > max_dense_points)
    throw Error(
        "mapper 'rbf' with the global basis " + std::string(basis_name(basis_)) + ": meshes '" +
        from.name() + "' (" + std::to_string(from.size()) + " points) and '" + to.name() + "' (" +
        std::to_string(to.size()) + " points) are too large for a dense system (at most " +
        std::to_string(max_dense_points) + "); use basis wendland-c2 with a support_radius");

  auto sys = std::make_unique<System>();
  sys->dense = dense;
  const Eigen::Index n = centres.size();
  const Eigen::Index m = points.size();
  sys->n = n;
  const Mesh::Points& xc = centres.points();
  const Mesh::Points& xe = points.points();

  // --- polynomial: 1 and the principal directions of the centres that have extent ---------
  if (polynomial_ != Polynomial::off) {
    std::vector<Eigen::Index> all(static_cast<std::size_t>(n));
    std::iota(all.begin(), all.end(), Eigen::Index{0});
    const LocalFrame frame = local_frame(xc, all, 1e-6);
    const int d = std::min<int>(frame.dims(), static_cast<int>(n) - 1);
    sys->q = 1 + d;
    auto basis_rows = [&](const Mesh::Points& x) {
      Eigen::MatrixXd p(x.rows(), sys->q);
      p.col(0).setOnes();
      if (d > 0)
        p.rightCols(d) = ((x.rowwise() - frame.origin.transpose()) * frame.axes).leftCols(d);
      return p;
    };
    sys->poly_centres = basis_rows(xc);
    sys->poly_eval = basis_rows(xe);
    if (polynomial_ == Polynomial::separate) {
      // c = (P^T P)^-1 P^T f; centred principal coordinates make P^T P diagonal
      const Eigen::MatrixXd ptp = sys->poly_centres.transpose() * sys->poly_centres;
      sys->pinv = ptp.ldlt().solve(sys->poly_centres.transpose());
    }
  }
  const int q = sys->q;
  const bool saddle = polynomial_ == Polynomial::on;

  auto phi = [this](double r) {
    switch (basis_) {
      case Basis::wendland_c2: {
        // phi(r) = (1 - r/R)^4 (4 r/R + 1), r < R
        const double s = r / radius_;
        if (s >= 1.0) return 0.0;
        const double t = 1.0 - s;
        return t * t * t * t * (4.0 * s + 1.0);
      }
      case Basis::gaussian: {
        const double s = r / radius_;
        return std::exp(-s * s);
      }
      case Basis::thin_plate_spline:
        return r > 0.0 ? r * r * std::log(r) : 0.0;
    }
    return 0.0;
  };

  if (!dense) {
    const PointTree tree(xc);
    std::vector<std::pair<std::uint32_t, double>> found;
    // K = [Phi P; P^T 0] (on) or Phi (separate, off), Phi_ij = phi(|x_i - x_j|)
    std::vector<Eigen::Triplet<double>> k;
    k.reserve(static_cast<std::size_t>(n) * 16);
    for (Eigen::Index i = 0; i < n; ++i) {
      tree.within(xc.row(i).transpose(), radius_, found);
      for (const auto& [j, d2] : found)
        if (static_cast<Eigen::Index>(j) >= i)  // LDL^T reads the lower triangle
          k.emplace_back(static_cast<Eigen::Index>(j), i, phi(std::sqrt(d2)));
    }
    const double neighbours = static_cast<double>(k.size()) / static_cast<double>(n) * 2.0 - 1.0;
    if (neighbours < 2.0)
      log::get("coupling")
          ->warn(
              "rbf from '{}' to '{}': support_radius {} m reaches only {:.1f} other points per "
              "centre on average; "
              "about 3 to 5 mesh spacings (10 to 30 neighbours) interpolate better",
              from.name(), to.name(), radius_, neighbours);
    System::SparseCol kk(n, n);
    kk.setFromTriplets(k.begin(), k.end());
    k = {};
    const bool use_cg =
        solver_ == Solver::cg || (solver_ == Solver::automatic && n > automatic_cg_threshold);
    if (!use_cg) {
      sys->ldlt.compute(kk);
      if (sys->ldlt.info() != Eigen::Success || sys->ldlt.vectorD().minCoeff() <= 0.0)
        throw Error("mapper 'rbf': the interpolation matrix on mesh '" + centres.name() +
                    "' is not positive definite (duplicate points?)");
    } else {
      sys->iterative = true;
      sys->phi = std::move(kk);
      sys->cg.setTolerance(tolerance_);
      sys->cg.setMaxIterations(std::max<Eigen::Index>(1000, n / 10));
      sys->cg.compute(sys->phi);
      if (sys->cg.info() != Eigen::Success)
        throw Error("mapper 'rbf': the incomplete Cholesky preconditioner failed on mesh '" +
                    centres.name() + "' (duplicate points?); use solver: cholesky");
    }
    if (saddle) {
      // Y = Phi^-1 P_C and the Schur complement S = P_C^T Y of the saddle-point system
      sys->phi_inv_p = sys->solve(sys->poly_centres);
      sys->schur.compute(sys->poly_centres.transpose() * sys->phi_inv_p);
      if (sys->schur.info() != Eigen::Success)
        throw Error("mapper 'rbf': the polynomial part on mesh '" + centres.name() +
                    "' is singular");
    }
    // E_ij = phi(|y_i - x_j|), y_i the evaluation points
    std::vector<Eigen::Triplet<double>> e;
    e.reserve(static_cast<std::size_t>(m) * 16);
    for (Eigen::Index i = 0; i < m; ++i) {
      tree.within(xe.row(i).transpose(), radius_, found);
      for (const auto& [j, d2] : found) {
        const double v = phi(std::sqrt(d2));
        if (v != 0.0) e.emplace_back(i, static_cast<Eigen::Index>(j), v);
      }
    }
    sys->eval.resize(m, n);
    sys->eval.setFromTriplets(e.begin(), e.end());
    sys->eval.makeCompressed();
  } else {
    const Eigen::Index size = n + (saddle ? q : 0);
    Eigen::MatrixXd kk = Eigen::MatrixXd::Zero(size, size);
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < n; ++i) kk(i, j) = phi((xc.row(i) - xc.row(j)).norm());
    if (saddle) {
      kk.topRightCorner(n, q) = sys->poly_centres;
      kk.bottomLeftCorner(q, n) = sys->poly_centres.transpose();
    }
    sys->dense_lu.compute(kk);
    const double rcond = sys->dense_lu.rcond();
    if (!(rcond > 1e-15))
      throw Error("mapper 'rbf' (" + std::string(basis_name(basis_)) +
                  "): the interpolation system on mesh '" + centres.name() +
                  "' is singular or too ill-conditioned (reciprocal condition " +
                  std::to_string(rcond) + "); use a smaller length scale or basis wendland-c2");
    sys->eval_dense.resize(m, n);
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < m; ++i)
        sys->eval_dense(i, j) = phi((xe.row(i) - xc.row(j)).norm());
  }
  system_ = std::move(sys);
  set_meshes(from, to);
}

void RbfMapper::map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const {
  check_input(in);
  const System& s = *system_;
  const int q = s.q;
  if (constraint_ == Constraint::consistent) {
    switch (polynomial_) {
      case Polynomial::off:
        // out = E Phi^-1 f
        out = s.apply_eval(s.solve(in));
        break;
      case Polynomial::separate: {
        // c = P^+ f,  alpha = Phi^-1 (f - P_C c),  out = E alpha + P_X c
        const Eigen::MatrixXd c = s.pinv * in;
        out = s.apply_eval(s.solve(in - s.poly_centres * c));
        out.noalias() += s.poly_eval * c;
        break;
      }
      case Polynomial::on: {
        // [alpha; c] = K^-1 [f; 0],  out = E alpha + P_X c
        Eigen::MatrixXd alpha, c;
        s.solve_saddle(in, Eigen::MatrixXd::Zero(q, in.cols()), alpha, c);
        out = s.apply_eval(alpha);
        out.noalias() += s.poly_eval * c;
        break;
      }
    }
  } else {
    // the transpose of the consistent operator from `to` (the centres) to `from`
    switch (polynomial_) {
      case Polynomial::off:
        out = s.solve(s.apply_eval_transposed(in));
        break;
      case Polynomial::separate: {
        // W = E Phi^-1 (I - P_C P^+) + P_X P^+  =>  W^T g = (I - P^+T P_C^T) a + P^+T P_X^T g,
        // a = Phi^-1 E^T g
        const Eigen::MatrixXd a = s.solve(s.apply_eval_transposed(in));
        const Eigen::MatrixXd pc = s.poly_eval.transpose() * in - s.poly_centres.transpose() * a;
        out = a;
        out.noalias() += s.pinv.transpose() * pc;
        break;
      }
      case Polynomial::on: {
        // W^T g = [I 0] K^-1 [E^T g; P_X^T g]   (K symmetric)
        Eigen::MatrixXd c;
        s.solve_saddle(s.apply_eval_transposed(in), s.poly_eval.transpose() * in, out, c);
        break;
      }
    }
  }
}

}  // namespace partita::coupling
