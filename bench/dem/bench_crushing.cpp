// bench_crushing: a crushing bed, the neighbour lists searched again at every breakage
// (breakage.lists: search) against fragments inserted into the lists (breakage.lists: local).
// The seed-000 granules (4.0, 3.125, 2.5 mm, equal numbers, expanded glass as the double hull's
// seeds' section has them: E 4 GPa, nu 0.22, 2500 kg/m^3 here for a short step) at porosity 0.5
// in a box, a platen (a plane) pressed down into them at 2 m/s, the seeds' strength law
// (20 MPa at 4 mm, Weibull m 10, fragments equal-4 down to 2 mm, mass restored). Both runs
// start from the same bed and take the same steps; the first `--settle` steps (same in both,
// nothing breaks yet) are not timed. Prints per run: seconds, steps/s, particle-steps/s,
// breakage events, list builds, local insertions, the energy balance error (--energy), and the
// ratio of the two times.
// Wall-clock on a possibly shared machine: read with care.
//
// usage: bench_crushing [--granules N] [--steps S] [--settle S] [--energy] [--only search|local]
// (--energy: with the energy accounting, as the double hull's cases run)

#include "partita/dem/breakage.hpp"
#include "partita/dem/packing_generator.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/system.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

using namespace partita::dem;

namespace {

struct Result {
  double seconds = 0.0;
  long steps = 0, events = 0, builds = 0, local = 0, particles = 0;
  double balance = 0.0;  // energy balance error (--energy)
};

Result run(const Packing& pk, double box, bool local, long settle, long steps, bool energy) {
  System sys;
  const int glass = sys.add_material({4.0e9, 0.22, 2500.0});
  sys.add_interaction(glass, glass, {0.5, 0.5, 0.1});
  sys.set_gravity({0, 0, -9.81});
  sys.add_particles(pk.positions, pk.radii, glass);
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2.0 * box), glass, 0b011111);
  double top = 0.0;
  for (std::size_t i = 0; i < sys.particle_count(); ++i)
    top = std::max(top, pk.positions(static_cast<Eigen::Index>(i), 2) + pk.radii[static_cast<Eigen::Index>(i)]);
  // the platen starts on the bed's top and moves down at 2 m/s
  const int platen = sys.add_plane({0, 0, top}, {0, 0, -1}, glass, {0, 0, -2.0});
  (void)platen;
  sys.set_sort_interval(10);
  sys.set_local_fragment_insertion(local);
  sys.set_energy_tracking(energy);
  BreakageParameters b;
  b.limit_strength = 20e6;
  b.reference_size = 4e-3;
  b.weibull_modulus = 10.0;
  b.comminution_limit = 2e-3;
  b.pattern = FragmentPattern::Kind::equal_4;
  b.restore_mass = true;
  sys.add_hook(std::make_unique<Breakage>(b));
  const double dt0 = 0.1 * sys.rayleigh_time_step();
  auto step = [&] { sys.step(std::min(dt0, 0.1 * sys.rayleigh_time_step())); };
  for (long s = 0; s < settle; ++s) step();
  const long builds0 = sys.neighbor_list().build_count();
  const auto t0 = std::chrono::steady_clock::now();
  long particle_steps = 0;
  for (long s = 0; s < steps; ++s) {
    step();
    particle_steps += static_cast<long>(sys.particle_count());
  }
  Result r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.steps = steps;
  r.events = static_cast<const Breakage&>(sys.hook(0)).counters().events;
  r.builds = sys.neighbor_list().build_count() - builds0;
  r.local = sys.local_insertions();
  r.particles = particle_steps / std::max(steps, 1L);
  r.balance = energy ? sys.energy_balance_error() : 0.0;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  double granules = 50000;
  long steps = 400, settle = 100;
  bool energy = false;
  std::string only;  // search or local: that run alone (for a profiler)
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--granules" && i + 1 < argc) {
      granules = std::stod(argv[++i]);
    } else if (a == "--steps" && i + 1 < argc) {
      steps = std::stol(argv[++i]);
    } else if (a == "--settle" && i + 1 < argc) {
      settle = std::stol(argv[++i]);
    } else if (a == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "--energy") {
      energy = true;
    } else {
      std::fprintf(stderr, "usage: bench_crushing [--granules N] [--steps S] [--settle S] [--energy] [--only search|local]\n");
      return 2;
    }
  }
  const std::vector<double> d{4.0e-3, 3.125e-3, 2.5e-3};
  double mean_vol = 0.0;
  for (double x : d) mean_vol += std::numbers::pi / 6.0 * x * x * x / static_cast<double>(d.size());
  const double porosity = 0.5;
  const double box = std::cbrt(granules * mean_vol / (1.0 - porosity));
  PackingSpec spec;
  spec.lo = Eigen::Vector3d::Zero();
  spec.hi = Eigen::Vector3d(box, box, box);
  spec.diameters = d;
  spec.fractions = {1.0, 1.0, 1.0};
  spec.porosity = porosity;
  spec.seed = 1;
  const Packing pk = PackingGenerator::generate(spec);
  std::printf("bench_crushing: %ld granules in a %.3f m box, platen at 2 m/s, %d thread(s); %ld steps "
              "untimed, %ld timed%s\n",
              static_cast<long>(pk.radii.size()), box, max_threads(), settle, steps,
              energy ? ", energy accounting" : "");
  std::printf("%-8s %9s %9s %14s %8s %8s %8s %10s %9s\n", "lists", "time [s]", "steps/s",
              "particle-st/s", "events", "builds", "local", "particles", "balance");
  Result r[2];
  for (int k = 0; k < 2; ++k) {
    if (!only.empty() && only != (k == 1 ? "local" : "search")) continue;
    r[k] = run(pk, box, k == 1, settle, steps, energy);
    std::printf("%-8s %9.2f %9.1f %14.3e %8ld %8ld %8ld %10ld %9.2e\n", k == 1 ? "local" : "search",
                r[k].seconds, r[k].steps / r[k].seconds, r[k].particles * r[k].steps / r[k].seconds,
                r[k].events, r[k].builds, r[k].local, r[k].particles, r[k].balance);
  }
  if (only.empty()) std::printf("ratio search/local time: %.2f\n", r[0].seconds / r[1].seconds);
  return 0;
}
