// Compute and map times of the data mappers on the 20 mm x 20 mm plate: source and target are
// non-matching triangulations of similar size (perturbed grids of different resolution), from
// 10^3 to 10^6 points (rbf to 10^5). Prints the time per point, the time relative to sorting n
// doubles (an n log n reference measured on the same machine, to see through the noise of a
// shared machine), and the fitted growth exponent (log-log slope) of compute and map: about 1
// (n log n) is the goal; 2 would mean an all-pairs loop somewhere.
//
// Then area-balanced between 10^4 and 10^6 interface cells: STL-like triangle centres
// (weights: areas) to the 2 x 2 Gauss points of a non-matching quad grid (weights: h^2/4), as on
// the seed's traction route. Prints set-up time per 10^5 cells (goal: under 1 s), the entries,
// and the balance errors: max_q |sum_i W_qi - 1| (rows), max_i |sum_q w_q W_qi - c_i| / c_i
// (columns) and the integral error of a spiky density (30 cells of 1000 per 10^4 loaded).
//
//   bench_mapping [--quick] [--max-n N] [--rbf-max-n N] [--area-max-n N] [--area-only] [--repeat R]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "partita/coupling/mapping/area_balanced_mapper.hpp"
#include "partita/coupling/mapping/mapper.hpp"
#include "partita/coupling/mapping/register_mappers.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;

namespace {

constexpr double plate = 0.02;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// (n+1)^2 nodes of the plate, interior perturbed by 0.3 spacing, two triangles per cell.
Mesh plate_mesh(const std::string& name, int n, unsigned seed, bool triangles) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const double h = plate / n;
  Mesh::Points p((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double dx = u(rng), dy = u(rng);
      p.row(j * (n + 1) + i) << i * h + (i > 0 && i < n ? dx * h : 0.0),
          j * h + (j > 0 && j < n ? dy * h : 0.0), 0.0;
    }
  Mesh::Triangles t(triangles ? 2 * n * n : 0, 3);
  if (triangles)
    for (int j = 0, k = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
        t.row(k++) << a, b, c;
        t.row(k++) << a, c, d;
      }
  return Mesh(name, p, t);
}

/// Time of std::sort on n random doubles (the n log n yardstick).
double sort_time(Eigen::Index n) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> v(static_cast<std::size_t>(n));
  double best = 1e300;
  for (int r = 0; r < 3; ++r) {
    for (auto& x : v) x = u(rng);
    const auto t0 = std::chrono::steady_clock::now();
    std::sort(v.begin(), v.end());
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

double slope(const std::vector<double>& n, const std::vector<double>& t) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double m = static_cast<double>(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    const double x = std::log(n[i]), y = std::log(t[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

/// Triangle centroids of plate_mesh(n) with the triangle areas as weights (STL cell centres).
Mesh centre_mesh(int n, unsigned seed) {
  const Mesh tri = plate_mesh("cells", n, seed, true);
  const Mesh::Points c = tri.triangle_centroids();
  Eigen::VectorXd a(tri.triangles().rows());
  for (Eigen::Index t = 0; t < a.size(); ++t) {
    const Eigen::Vector3d p0 = tri.points().row(tri.triangles()(t, 0));
    const Eigen::Vector3d p1 = tri.points().row(tri.triangles()(t, 1));
    const Eigen::Vector3d p2 = tri.points().row(tri.triangles()(t, 2));
    a(t) = 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  Mesh m("cell_centres", c);
  m.set_weights(a);
  return m;
}

/// 2 x 2 Gauss points of an m x m quad grid on the plate, weights (h/2)^2 (FE quadrature).
Mesh gauss_mesh(int m) {
  const double h = plate / m, g = h / (2.0 * std::sqrt(3.0));
  Mesh::Points q(4 * static_cast<Eigen::Index>(m) * m, 3);
  Eigen::Index k = 0;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
          q.row(k++) << (i + 0.5) * h + (a ? g : -g), (j + 0.5) * h + (b ? g : -g), 0.0;
  Mesh mesh("quadrature", q);
  mesh.set_weights(Eigen::VectorXd::Constant(q.rows(), h * h / 4));
  return mesh;
}

void bench_area_balanced(double max_n, int repeat) {
  std::printf(
      "\n# area-balanced: triangle centres (areas) -> 2x2 Gauss points of a quad grid; set-up "
      "per 1e5 cells = compute / (n_source / 1e5)\n");
  std::printf("%-28s %9s %9s %10s %12s %10s %10s %10s %10s %10s\n", "mapper", "n_source",
              "n_target", "compute[s]", "per 1e5[s]", "entries", "row err", "column err",
              "spiky err", "map[s]");
  for (const int neighbors : {1, 6})
    for (const double cells : {1e4, 1e5, 1e6}) {
      if (cells > max_n * 1.0001) break;
      const int n = static_cast<int>(std::lround(std::sqrt(cells / 2.0)));        // 2 n^2 triangles
      const int m = static_cast<int>(std::lround(std::sqrt(cells / 4.0 * 1.1)));  // ~10 % more
      const Mesh source = centre_mesh(n, 1);
      const Mesh target = gauss_mesh(m);
      AreaBalancedMapper mapper(Constraint::consistent, neighbors);
      auto t0 = std::chrono::steady_clock::now();
      mapper.compute(source, target);
      const double compute = seconds_since(t0);
      const auto& w = mapper.matrix();
      const Eigen::VectorXd ones = Eigen::VectorXd::Ones(source.size());
      const double row_err =
          (w * ones - Eigen::VectorXd::Ones(target.size())).cwiseAbs().maxCoeff();
      long double sw = 0.0L, sa = 0.0L;  // the totals to 1e-16 (double sums: 1e-13 at 1e5)
      for (const double x : target.weights()) sw += x;
      for (const double x : source.weights()) sa += x;
      const Eigen::VectorXd c = source.weights() * static_cast<double>(sw / sa);
      const Eigen::VectorXd col = w.transpose() * target.weights();
      const double col_err = ((col - c).array() / c.array()).abs().maxCoeff();
      // spiky density: 3 of every 1000 cells loaded (as DEM contacts on an STL)
      std::mt19937 rng(3);
      std::uniform_int_distribution<Eigen::Index> pick(0, source.size() - 1);
      Eigen::MatrixXd t = Eigen::MatrixXd::Zero(source.size(), 3);
      for (Eigen::Index k = 0; k < source.size() / 333 + 1; ++k) t(pick(rng), 2) = -1.0e4;
      Eigen::MatrixXd out;
      mapper.map(t, out);
      const double sent = c.dot(t.col(2));
      const double spiky = std::abs(target.weights().dot(out.col(2)) - sent) / std::abs(sent);
      t0 = std::chrono::steady_clock::now();
      for (int r = 0; r < repeat; ++r) mapper.map(t, out);
      const double map = seconds_since(t0) / repeat;
      const std::string label = "area-balanced neighbors " + std::to_string(neighbors);
      std::printf("%-28s %9ld %9ld %10.4f %12.4f %10ld %10.2e %10.2e %10.2e %10.5f\n",
                  label.c_str(), static_cast<long>(source.size()), static_cast<long>(target.size()),
                  compute, compute / (static_cast<double>(source.size()) / 1e5),
                  static_cast<long>(w.nonZeros()), row_err, col_err, spiky, map);
      std::fflush(stdout);
    }
}

struct Case {
  std::string label;
  std::string yaml;  // the mapper node
  bool source_triangles;
  Constraint constraint;
  bool rbf;
};

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, area_only = false;
  double max_n = 1.0e6, rbf_max_n = 1.0e5, area_max_n = 1.0e6;
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--area-only") {
      area_only = true;
    } else if (a == "--max-n" && i + 1 < argc) {
      max_n = std::atof(argv[++i]);
    } else if (a == "--rbf-max-n" && i + 1 < argc) {
      rbf_max_n = std::atof(argv[++i]);
    } else if (a == "--area-max-n" && i + 1 < argc) {
      area_max_n = std::atof(argv[++i]);
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr,
                   "usage: bench_mapping [--quick] [--max-n N] [--rbf-max-n N] [--area-max-n N] "
                   "[--area-only] [--repeat R]\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  if (quick) max_n = rbf_max_n = area_max_n = 1.0e4, repeat = 2;

  Registry<MapperFactory> registry("mapper");
  register_mappers(registry);
  // Support radius of the compact RBF: 3 source spacings (about 28 neighbours), scaled per size.
  std::vector<Case> cases = {
      {"nearest-neighbor", "nearest-neighbor", true, Constraint::consistent, false},
      {"nearest-projection", "nearest-projection", true, Constraint::consistent, false},
      {"nearest-projection (conservative)", "nearest-projection", true, Constraint::conservative,
       false},
      {"nearest-projection (point cloud)", "nearest-projection", false, Constraint::consistent,
       false},
      {"rbf wendland-c2 separate (default: auto solver)", "{type: rbf, support_radius: @}", true,
       Constraint::consistent, true},
      {"rbf wendland-c2 separate cholesky", "{type: rbf, support_radius: @, solver: cholesky}",
       true, Constraint::consistent, true},
      {"rbf wendland-c2 on", "{type: rbf, support_radius: @, polynomial: on}", true,
       Constraint::consistent, true},
  };
  cases.push_back({"rbf wendland-c2 separate cg", "{type: rbf, support_radius: @, solver: cg}",
                   true, Constraint::consistent, true});
  const std::vector<double> sizes = {1e3, 3e3, 1e4, 3e4, 1e5, 3e5, 1e6};

  std::printf(
      "# partita mapping benchmark: plate %.0f mm, source/target non-matching perturbed "
      "triangulations\n",
      plate * 1e3);
  std::printf(
      "# times: compute once; map = mean of %d maps of a 3-component field. 'x sort' = time / "
      "std::sort(n doubles)\n",
      repeat);
  std::printf("%-36s %9s %9s %10s %12s %9s %10s %12s %9s\n", "mapper", "n_source", "n_target",
              "compute[s]", "compute/pt", "x sort", "map[s]", "map/pt", "x sort");
  if (area_only) cases.clear();
  for (const Case& c : cases) {
    std::vector<double> ns, tc, tm;
    for (double size : sizes) {
      if (size > (c.rbf ? rbf_max_n : max_n) * 1.0001) break;
      const int n_src = static_cast<int>(std::lround(std::sqrt(size))) - 1;
      const int n_tgt =
          static_cast<int>(std::lround(std::sqrt(1.1 * size))) - 1;  // ~10 % more points
      const Mesh source_tri = plate_mesh("source", n_src, 1, true);
      const Mesh source =
          c.source_triangles ? source_tri : Mesh("source_centres", source_tri.triangle_centroids());
      const Mesh target = plate_mesh("target", n_tgt, 2, true);
      std::string yaml = c.yaml;
      if (const auto at = yaml.find('@'); at != std::string::npos)
        yaml.replace(at, 1, std::to_string(3.0 * plate / n_src));
      try {
        const config::Node node =
            config::Node::load_string("mapper: " + yaml + "\n", "bench")["mapper"];
        auto mapper = create_mapper(registry, MapperContext{node, c.constraint});
        auto t0 = std::chrono::steady_clock::now();
        mapper->compute(source, target);
        const double compute = seconds_since(t0);
        const Eigen::MatrixXd in = Eigen::MatrixXd::Random(source.size(), 3);
        Eigen::MatrixXd out;
        mapper->map(in, out);  // warm-up (sizes `out`)
        t0 = std::chrono::steady_clock::now();
        for (int r = 0; r < repeat; ++r) mapper->map(in, out);
        const double map = seconds_since(t0) / repeat;
        const double n = static_cast<double>(std::max(source.size(), target.size()));
        const double ref = sort_time(static_cast<Eigen::Index>(n));
        std::printf("%-36s %9ld %9ld %10.4f %9.3f us %9.1f %10.5f %9.1f ns %9.2f\n",
                    c.label.c_str(), static_cast<long>(source.size()),
                    static_cast<long>(target.size()), compute, compute / n * 1e6, compute / ref,
                    map, map / n * 1e9, map / ref);
        std::fflush(stdout);
        ns.push_back(n);
        tc.push_back(compute);
        tm.push_back(map);
      } catch (const partita::Error& e) {
        std::printf("%-36s %9ld: %s\n", c.label.c_str(), static_cast<long>(source.size()),
                    e.what());
      }
    }
    if (ns.size() >= 2)
      std::printf(
          "%-36s growth exponent (log-log slope): compute %.2f, map %.2f  (n log n over this "
          "range: %.2f)\n\n",
          c.label.c_str(), slope(ns, tc), slope(ns, tm), [&] {
            std::vector<double> nl;
            for (double n : ns) nl.push_back(n * std::log(n));
            return slope(ns, nl);
          }());
  }
  bench_area_balanced(area_max_n, repeat);
  return 0;
}
