#include "partita/coupling/mapping/area_balanced_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "point_tree.hpp"

namespace partita::coupling {

std::shared_ptr<const config::Spec> AreaBalancedMapper::spec() {
  auto s = std::make_shared<config::Spec>(
      "area-balanced",
      "consistent and integral-preserving mapping of densities between weighted point sets (cell "
      "centres <-> quadrature points)");
  s->string("type", "the mapper's name, when the mapper is given as a map");
  s->integer("neighbors",
             "k > 1: also smooth over each source point's k nearest source points (both "
             "properties kept); 1: no smoothing, the fewest entries")
      .min(1)
      .max(64)
      .def(1);
  return s;
}

std::unique_ptr<Mapper> AreaBalancedMapper::create(const MapperContext& context) {
  const config::Node o = mapper_options(context.config, spec());
  const int k = static_cast<int>(o.integer("neighbors"));
  return std::make_unique<AreaBalancedMapper>(context.constraint, k);
}

namespace {

long double accurate_sum(const Eigen::VectorXd& v) {
  long double sum = 0.0L;
  for (const double x : v) sum += x;
  return sum;
}

struct Piece {
  std::int32_t index;  // point of the mesh
  double mass;         // the part of its weight this piece carries
};

/// A node of the bisection: target pieces [t0, t1) and source pieces [s0, s1) of one level's
/// arrays, of equal total mass.
struct Range {
  std::size_t t0, t1, s0, s1;
};

/// Append pieces[0..n) to `out` as two runs of half the total mass each: the pieces below the
/// half go left, the one that straddles it is cut in two. Returns the end of the left run.
/// The pieces are sorted along the cut's axis and carry positive masses.
std::size_t append_halves(const Piece* pieces, std::size_t n, std::vector<Piece>& out) {
  // Sums in long double (64-bit mantissa on x86-64): the cut part half - below is a difference
  // of sums over the whole node, whose rounding would otherwise show in small pieces (1e-12
  // relative at 10^5 points, measured; 1e-16 with the wider sums).
  long double total = 0.0L;
  for (std::size_t i = 0; i < n; ++i) total += pieces[i].mass;
  const long double half = 0.5L * total;
  long double below = 0.0L;
  std::size_t k = 0;
  while (k + 1 < n && below + pieces[k].mass <= half) below += pieces[k++].mass;
  out.insert(out.end(), pieces, pieces + k);
  // pieces[k] straddles the half: half - below of it lies left (> 0 unless below == half)
  const double part = std::clamp(static_cast<double>(half - below), 0.0, pieces[k].mass);
  if (part > 0.0) out.push_back({pieces[k].index, part});
  const std::size_t left_end = out.size();
  out.push_back({pieces[k].index, pieces[k].mass - part});
  out.insert(out.end(), pieces + k + 1, pieces + n);
  return left_end;
}

/// The transport plan P (target x source) with row sums w and column sums c (equal totals) by
/// recursive bisection, as triplets (duplicates to be summed).
void bisection_plan(const Mesh::Points& target, const Eigen::VectorXd& w,
                    const Mesh::Points& source, const Eigen::VectorXd& c,
                    std::vector<Eigen::Triplet<double>>& plan) {
  std::vector<Piece> t, s, t_next, s_next;
  for (Eigen::Index q = 0; q < w.size(); ++q)
    if (w(q) > 0.0) t.push_back({static_cast<std::int32_t>(q), w(q)});
  for (Eigen::Index i = 0; i < c.size(); ++i)
    if (c(i) > 0.0) s.push_back({static_cast<std::int32_t>(i), c(i)});
  std::vector<Range> nodes = {{0, t.size(), 0, s.size()}}, next;
  while (!nodes.empty()) {
    t_next.clear();
    s_next.clear();
    next.clear();
    for (const Range& r : nodes) {
      const std::size_t nt = r.t1 - r.t0, ns = r.s1 - r.s0;
      if (nt == 1 || ns == 1) {
        // one point on a side takes the other side's pieces whole: P_qi += mass
        for (std::size_t a = r.t0; a < r.t1; ++a)
          for (std::size_t b = r.s0; b < r.s1; ++b)
            plan.emplace_back(t[a].index, s[b].index, nt == 1 ? s[b].mass : t[a].mass);
        continue;
      }
      // cut across the longest side of the bounding box of both point sets
      Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
      Eigen::Array3d hi = -lo;
      for (std::size_t a = r.t0; a < r.t1; ++a) {
        lo = lo.min(target.row(t[a].index).transpose().array());
        hi = hi.max(target.row(t[a].index).transpose().array());
      }
      for (std::size_t b = r.s0; b < r.s1; ++b) {
        lo = lo.min(source.row(s[b].index).transpose().array());
        hi = hi.max(source.row(s[b].index).transpose().array());
      }
      Eigen::Index axis = 0;
      (hi - lo).maxCoeff(&axis);
      auto along = [axis](const Mesh::Points& x) {
        return [&x, axis](const Piece& a, const Piece& b) {
          const double xa = x(a.index, axis), xb = x(b.index, axis);
          return xa < xb || (xa == xb && a.index < b.index);
        };
      };
      std::sort(t.begin() + static_cast<std::ptrdiff_t>(r.t0),
                t.begin() + static_cast<std::ptrdiff_t>(r.t1), along(target));
      std::sort(s.begin() + static_cast<std::ptrdiff_t>(r.s0),
                s.begin() + static_cast<std::ptrdiff_t>(r.s1), along(source));
      const std::size_t t0 = t_next.size();
      const std::size_t tm = append_halves(t.data() + r.t0, nt, t_next);
      const std::size_t s0 = s_next.size();
      const std::size_t sm = append_halves(s.data() + r.s0, ns, s_next);
      next.push_back({t0, tm, s0, sm});
      next.push_back({tm, t_next.size(), sm, s_next.size()});
    }
    t.swap(t_next);
    s.swap(s_next);
    nodes.swap(next);
  }
}

/// S (source x source): the balanced smoothing over the k nearest source points (see the
/// header): S 1 = 1, c^T S = c^T, S >= 0.
SparseMapper::Matrix smoothing(const Mesh::Points& x, const Eigen::VectorXd& c, int k) {
  const Eigen::Index n = x.rows();
  const PointTree tree(x);
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  std::vector<std::uint32_t> idx;
  std::vector<double> d2;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(c(i) > 0.0)) continue;
    tree.nearest(x.row(i).transpose(), static_cast<std::size_t>(k) + 1, idx, d2);
    for (const std::uint32_t j : idx)
      if (static_cast<Eigen::Index>(j) != i && c(j) > 0.0)
        edges.emplace_back(std::min<std::int32_t>(i, j), std::max<std::int32_t>(i, j));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Eigen::VectorXd degree = Eigen::VectorXd::Zero(n);
  for (const auto& [i, j] : edges) degree(i) += 1.0, degree(j) += 1.0;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * edges.size() + static_cast<std::size_t>(n));
  Eigen::VectorXd off = Eigen::VectorXd::Zero(n);  // sum_j e_ij / c_i
  for (const auto& [i, j] : edges) {
    // e_ij = 0.5 min(c_i / deg_i, c_j / deg_j): sum_j e_ij <= c_i / 2, so S_ii >= 1/2
    const double e = 0.5 * std::min(c(i) / degree(i), c(j) / degree(j));
    entries.emplace_back(i, j, e / c(i));
    entries.emplace_back(j, i, e / c(j));
    off(i) += e / c(i);
    off(j) += e / c(j);
  }
  for (Eigen::Index i = 0; i < n; ++i) entries.emplace_back(i, i, 1.0 - off(i));
  SparseMapper::Matrix m(n, n);
  m.setFromTriplets(entries.begin(), entries.end());
  return m;
}

}  // namespace

SparseMapper::Matrix AreaBalancedMapper::interpolation(const Mesh& source,
                                                       const Mesh& target) const {
  for (const Mesh* m : {&source, &target})
    if (!m->has_weights())
      throw Error(
          "mapper 'area-balanced' needs point weights (the area each point stands for) on both "
          "meshes, and mesh '" +
          m->name() +
          "' has none; it maps between cell-centre and "
          "quadrature-point meshes (e.g. a DEM mesh's <name>_centres and an FE interface's "
          "<name>_quadrature); use nearest-projection or rbf for other meshes");
  const Eigen::Index ns = source.size(), nt = target.size();
  const Eigen::VectorXd& a = source.weights();
  const Eigen::VectorXd& w = target.weights();
  if (a.sum() <= 0 || w.sum() <= 0)
    throw Error("mapper 'area-balanced': the point weights of mesh '" +
                (a.sum() <= 0 ? source.name() : target.name()) + "' sum to zero");
  if (std::max(ns, nt) > std::numeric_limits<std::int32_t>::max())
    throw Error("mapper 'area-balanced': more than 2^31 points");

  // P = diag(w) W: target q hands out w_q, source i receives c_i = A_i sum(w)/sum(A). The sums in
  // long double: the plan's rows and columns can be no closer to w and c than the two totals
  // agree (double sums of 10^5 weights: 1e-13 relative, measured).
  const Eigen::VectorXd c = a * static_cast<double>(accurate_sum(w) / accurate_sum(a));
  std::vector<Eigen::Triplet<double>> plan;
  plan.reserve(static_cast<std::size_t>(2 * (ns + nt)));
  bisection_plan(target.points(), w, source.points(), c, plan);

  // Diagnosis: the share of the weight moved farther than 4 spacings (meshes that do not cover
  // the same surface move weight across the gap).
  double far = 0.0;
  for (const auto& e : plan) {
    const double spacing2 = std::max(w(e.row()), a(e.col()));
    if ((target.points().row(e.row()) - source.points().row(e.col())).squaredNorm() >
        16.0 * spacing2)
      far += e.value();
  }
  if (far > 0.01 * w.sum())
    log::get("coupling")
        ->warn(
            "mapper 'area-balanced' from '{}' to '{}': {:.1f} % of the weight moves farther than "
            "4 point spacings; are the two meshes covering the same surface?",
            source.name(), target.name(), 100.0 * far / w.sum());

  // Row sums (w_q to round-off). Target points of zero weight draw on nothing: they take their
  // nearest source point (the row still sums to 1; with w_q = 0 they add nothing to the
  // integral).
  Eigen::VectorXd row = Eigen::VectorXd::Zero(nt);
  for (const auto& e : plan) row(e.row()) += e.value();
  if ((row.array() <= 0.0).any()) {
    const PointTree tree(source.points());
    for (Eigen::Index q = 0; q < nt; ++q)
      if (row(q) <= 0.0) {
        plan.emplace_back(q, tree.nearest(target.points().row(q).transpose()).first, 1.0);
        row(q) = 1.0;
      }
  }
  // W = diag(1/row sums) P: rows sum to 1 to round-off
  for (auto& e : plan) e = Eigen::Triplet<double>(e.row(), e.col(), e.value() / row(e.row()));
  Matrix m(nt, ns);
  m.setFromTriplets(plan.begin(), plan.end());
  m.makeCompressed();
  if (neighbors_ > 1 && ns > 1) m = Matrix(m * smoothing(source.points(), c, neighbors_));
  return m;
}

}  // namespace partita::coupling
