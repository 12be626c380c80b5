// bench_packing: the box filler (PackingGenerator) at growing sizes, the seed-000 granules
// (4.0, 3.125, 2.5 mm, equal numbers) at porosity 0.5 in a cube, as the cases use it.
// Prints per size: granules, seconds, relaxation sweeps, the realised porosity and largest
// overlap, the growth exponent of the time between successive sizes (t ~ N^a), and the ratio
// of the 10^6 time to the aim (15 s on 2 cores) and to an older generator's time (31 s on 16
// cores). Wall-clock on a possibly shared machine: read with care.
//
// usage: bench_packing [--sizes 1e4,1e5,1e6] [--porosity P] [--seed S]

#include "partita/dem/packing_generator.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace partita::dem;

int main(int argc, char** argv) {
  std::vector<double> sizes{1e4, 1e5, 1e6};
  double porosity = 0.5;
  std::uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      std::string item;
      while (std::getline(ss, item, ',')) sizes.push_back(std::stod(item));
    } else if (a == "--porosity" && i + 1 < argc) {
      porosity = std::stod(argv[++i]);
    } else if (a == "--seed" && i + 1 < argc) {
      seed = std::stoull(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: bench_packing [--sizes 1e4,1e5,1e6] [--porosity P] [--seed S]\n");
      return 2;
    }
  }
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  const std::vector<double> d{4.0e-3, 3.125e-3, 2.5e-3};
  double mean_vol = 0.0;
  for (double x : d) mean_vol += std::numbers::pi / 6.0 * x * x * x / d.size();
  std::printf("bench_packing: seed-000 granules, porosity %.3f, %d thread(s)\n", porosity, threads);
  std::printf("%10s %9s %10s %7s %10s %12s %9s\n", "granules", "box [m]", "time [s]", "sweeps",
              "porosity", "overlap/Rmin", "exponent");
  double prev_n = 0.0, prev_t = 0.0;
  for (double target : sizes) {
    const double box = std::cbrt(target * mean_vol / (1.0 - porosity));
    PackingSpec spec;
    spec.hi = Eigen::Vector3d(box, box, box);
    spec.diameters = d;
    spec.fractions = {1.0, 1.0, 1.0};
    spec.porosity = porosity;
    spec.seed = seed;
    if (std::getenv("PACK_TRACE"))
      spec.progress = [](int s, double o) { if (s % 10 == 0) std::fprintf(stderr, "  sweep %d overlap %.3g\n", s, o); };
    const auto t0 = std::chrono::steady_clock::now();
    const Packing p = PackingGenerator::generate(spec);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double n = static_cast<double>(p.radii.size());
    char expo[32] = "-";
    if (prev_n > 0.0) std::snprintf(expo, sizeof expo, "%.2f", std::log(t / prev_t) / std::log(n / prev_n));
    std::printf("%10.0f %9.4f %10.3f %7d %10.5f %12.2e %9s\n", n, box, t, p.sweeps, p.porosity,
                p.max_overlap / 1.25e-3, expo);
    std::fflush(stdout);
    if (n >= 0.99e6 && n <= 1.01e6)
      std::printf("  10^6 granules: %.2f s = %.2fx the aim (15 s on 2 cores), %.2fx the first "
                  "generator's time (31 s on 16 cores)\n", t, t / 15.0, t / 31.0);
    prev_n = n;
    prev_t = t;
  }
  return 0;
}
