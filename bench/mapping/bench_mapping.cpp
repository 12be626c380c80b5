// Compute and map times of the data mappers on the 20 mm x 20 mm plate: source and target are
// non-matching triangulations of similar size (perturbed grids of different resolution), from
// 10^3 to 10^6 points (rbf to 10^5). Prints the time per point, the time relative to sorting n
// doubles (an n log n reference measured on the same machine, to see through the noise of a
// shared machine), and the fitted growth exponent (log-log slope) of compute and map: about 1
// (n log n) is the goal; 2 would mean an all-pairs loop somewhere.
//
//   bench_mapping [--quick] [--max-n N] [--rbf-max-n N] [--repeat R]

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

struct Case {
  std::string label;
  std::string yaml;  // the mapper node
  bool source_triangles;
  Constraint constraint;
  bool rbf;
};

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  double max_n = 1.0e6, rbf_max_n = 1.0e5;
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--max-n" && i + 1 < argc) {
      max_n = std::atof(argv[++i]);
    } else if (a == "--rbf-max-n" && i + 1 < argc) {
      rbf_max_n = std::atof(argv[++i]);
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr,
                   "usage: bench_mapping [--quick] [--max-n N] [--rbf-max-n N] [--repeat R]\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  if (quick) max_n = rbf_max_n = 1.0e4, repeat = 2;

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
  return 0;
}
