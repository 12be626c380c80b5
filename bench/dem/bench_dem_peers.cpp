// DEM peer benchmark (shared/bench/peers/README.md, RESULTS.md): a settled bed of Hertz-Mindlin
// granules read from the common bed file, 500 untimed warm-up steps, then 20,000 (small) or 5,000
// (large) timed steps with 1 and 2 threads. Prints particle-steps/s, the mean number of
// particle-particle contacts per particle (peers: 4.14 small, 4.62 large) and the ratio to
// LIGGGHTS: measured in the same invocation when `liggghts` is on PATH, else the recorded figures.
//
// usage: bench_dem_peers [--data DIR] [--case small|large|all] [--threads 1,2] [--scaling]
//                        [--quick] [--vtk DIR] [--no-peer] [--shuffle] [--sort N] [--breakage]
//                        [--energy]  (the energy accounting on: System::set_energy_tracking)
// --scaling: the large bed (unless --case names another) on 1, 2, 4, ... threads up to the
// machine's processors (and that number), then the speed-up over 1 thread of each (the
// aim: 12x at 16 threads); particles renumbered in cell order
// every 10 list builds as in a partita run, unless --sort says otherwise. --profile (with or
// without --scaling) adds, after each plain line, where a step's wall time went thread by thread
// (System::step_profile(): the fork, each phase's busy time, mean and slowest thread, the waits at
// its barriers, the work of all threads against one thread's). With more than 2 threads
// the ratio to LIGGGHTS is printed only where LIGGGHTS ran (as many MPI ranks) in the same
// invocation.
// --shuffle numbers the bed's particles in a random order (as a data file written by another code
// may); --sort N renumbers them in cell order at the first step and every N-th list build
// (System::set_sort_interval; default 0: the file's order, which is already spatial).
// --breakage runs every line twice, plain and with the crushing model (Breakage) enabled but
// nothing breaking (strength far above any contact pressure of the bed), and prints the cost.
// Physics as the decks dem/liggghts/model.in + bench.in: E = 200 MPa, nu = 0.23, e = 0.5 with
// LIGGGHTS-style damping, mu = 0.3, Mindlin tangential history, walls x = 0, W, y = 0, W, z = 0
// of the same material, g = 9.81 m/s^2, dt = 1.9e-6 s, skin 0.5 mm.

#include "partita/adapters/dem_output.hpp"
#include "partita/dem/breakage.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/lammps_data.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/system.hpp"
#include "partita/interface/error.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace partita::dem;

namespace {

struct Case {
  std::string name;
  double width;
  long steps;
  double peer_contacts;
  double liggghts_1, liggghts_2;  // recorded particle-steps/s (RESULTS.md)
};

// --energy: the energy accounting on (System::set_energy_tracking)
bool g_energy = false;

System make_system(const LammpsData& d, double width, bool shuffle, int sort_interval,
                   bool breakage) {
  System sys;
  if (breakage) {  // enabled, nothing breaks: the cost of the criterion alone
    BreakageParameters b;
    b.limit_strength = 1.0e15;
    b.reference_size = 4.0e-3;
    b.weibull_modulus = 3.0;
    b.comminution_limit = 1.0e-3;
    sys.add_hook(std::make_unique<Breakage>(b));
  }
  std::map<double, int> material_of_density;
  for (double rho : d.density)
    if (!material_of_density.count(rho))
      material_of_density[rho] = sys.add_material({2.0e8, 0.23, rho});
  const int wall = material_of_density.begin()->second;
  for (const auto& [rho_a, a] : material_of_density)
    for (const auto& [rho_b, b] : material_of_density) sys.add_interaction(a, b, {0.3, 0.5, 0.0});
  sys.set_damping_model(DampingModel::liggghts);
  sys.set_gravity({0.0, 0.0, -9.81});
  sys.set_skin(0.5e-3);
  sys.set_sort_interval(sort_interval);
  std::vector<std::size_t> order(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) order[i] = i;
  if (shuffle) {  // a fixed pseudo-random permutation (64-bit LCG, Fisher-Yates)
    std::uint64_t state = 12345;
    for (std::size_t i = order.size() - 1; i > 0; --i) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      std::swap(order[i], order[(state >> 33) % (i + 1)]);
    }
  }
  for (std::size_t i : order)
    sys.add_particle(d.position[i], 0.5 * d.diameter[i], material_of_density[d.density[i]],
                     d.velocity[i], d.angular_velocity[i], d.id[i]);
  sys.add_plane({0, 0, 0}, {1, 0, 0}, wall);
  sys.add_plane({width, 0, 0}, {-1, 0, 0}, wall);
  sys.add_plane({0, 0, 0}, {0, 1, 0}, wall);
  sys.add_plane({0, width, 0}, {0, -1, 0}, wall);
  sys.add_plane({0, 0, 0}, {0, 0, 1}, wall);
  sys.set_energy_tracking(g_energy);
  return sys;
}

bool on_path(const std::string& exe) {
  return std::system(("command -v " + exe + " > /dev/null 2>&1").c_str()) == 0;
}

// Runs the LIGGGHTS deck as run_one.sh does; returns particle-steps/s of the timed run or 0.
double run_liggghts(const std::string& dem_dir, const Case& c, long n_atoms, int ranks,
                    long steps) {
  const std::string log = (std::filesystem::temp_directory_path() /
                           ("bench_dem_liggghts_" + c.name + std::to_string(ranks) + ".log"))
                              .string();
  std::ostringstream cmd;
  cmd << "cd '" << dem_dir << "/liggghts' && OMP_NUM_THREADS=1 "
      << (ranks > 1 ? "mpirun --allow-run-as-root -np " + std::to_string(ranks) + " --bind-to core "
                    : std::string())
      << "liggghts -in bench.in -var data ../data/bed_" << c.name << ".data -var W " << c.width
      << " -var nsteps " << steps << " -log '" << log << "' -screen none > /dev/null 2>&1";
  if (std::system(cmd.str().c_str()) != 0) return 0.0;
  std::ifstream in(log);
  std::string line;
  int seen = 0;
  while (std::getline(in, line)) {
    if (line.rfind("Loop time", 0) != 0) continue;
    if (++seen == 2) {  // the first is the warm-up run
      std::istringstream is(line);
      std::string w;
      double seconds = 0.0;
      is >> w >> w >> w >> seconds;
      return seconds > 0.0 ? static_cast<double>(n_atoms) * steps / seconds : 0.0;
    }
  }
  return 0.0;
}

std::string fmt_ratio(double r) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2fx", r);
  return b;
}

// The speed-up over the 1-thread run of each other thread count, and the parallel efficiency.
void print_scaling(const std::string& bed, const std::vector<std::pair<int, double>>& rates) {
  double one = 0.0;
  for (const auto& [t, r] : rates)
    if (t == 1) one = r;
  if (one <= 0.0 || rates.size() < 2) return;
  std::printf("# %s bed, thread scaling (particle-steps/s over 1 thread's; efficiency):",
              bed.c_str());
  for (const auto& [t, r] : rates)
    if (t != 1) std::printf("  %d: %.2fx (%.0f %%)", t, r / one, 100.0 * r / one / t);
  std::printf("\n");
  for (const auto& [t, r] : rates)
    if (t == 16)
      std::printf("# the aim at 16 threads: 12x (the first threaded DEM: 9.7x); here %.2fx\n",
                  r / one);
  std::fflush(stdout);
}

// One line per run: where a fused step's wall time went (System::StepProfile), in us per step.
// busy_one: the busy time per fused step of the 1-thread run (0: not known), for the work of all
// threads against one thread's.
void print_profile(int nt, const System::StepProfile& p, double busy_one) {
  if (p.fused_steps == 0) {
    std::printf("# profile %d thr: no fused step\n", nt);
    return;
  }
  const double per = 1e6 / static_cast<double>(p.fused_steps);  // s in total -> us a step
  int team = 0;
  double mean[7] = {}, most[7] = {};
  for (const System::StepProfile::Thread& t : p.threads) {
    if (t.enter + t.busy() + t.join_wait == 0.0) continue;
    ++team;
    const double v[7] = {t.enter, t.drift, t.drift_wait, t.cross, t.cross_wait, t.rows, t.join_wait};
    for (int k = 0; k < 7; ++k) mean[k] += v[k], most[k] = std::max(most[k], v[k]);
  }
  for (double& m : mean) m /= std::max(team, 1);
  const double busy = mean[1] + mean[3] + mean[5];
  std::printf(
      "# profile %d thr (%d in the team), us per fused step (%ld of %ld steps; the others %.1f us): "
      "step %.1f = outside the region %.1f + region %.1f; in the region, mean/slowest thread: "
      "fork %.1f/%.1f, drift %.1f/%.1f, wait %.1f, cross %.1f/%.1f, wait %.1f, rows %.1f/%.1f, "
      "then waiting %.1f for the step's slowest thread (done at %.1f) and the join (%.1f); "
      "busy %.1f a thread",
      nt, team, p.fused_steps, p.steps,
      p.steps > p.fused_steps
          ? 1e6 * (p.step_s - p.fused_step_s) / static_cast<double>(p.steps - p.fused_steps)
          : 0.0,
      p.fused_step_s * per, (p.fused_step_s - p.fused_region_s) * per, p.fused_region_s * per,
      mean[0] * per, most[0] * per, mean[1] * per, most[1] * per, mean[2] * per, mean[3] * per,
      most[3] * per, mean[4] * per, mean[5] * per, most[5] * per, mean[6] * per,
      p.fused_slowest_s * per, (p.fused_region_s - p.fused_slowest_s) * per, busy * per);
  if (busy_one > 0.0)
    std::printf(", all threads' work %.2fx one thread's", busy * team * per / busy_one);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string dem_dir = PARTITA_PEER_DEM_DIR;
  std::string data_dir = dem_dir + "/data";
  std::string which = "all", vtk_dir;
  std::vector<int> threads = {1, 2};
  bool quick = false, no_peer = false, shuffle = false, breakage = false, scaling = false;
  bool case_given = false, sort_given = false, profile = false;
  int sort_interval = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    auto next = [&]() -> std::string {
      if (a + 1 >= argc) {
        std::cerr << "bench_dem_peers: " << arg << " needs a value\n";
        std::exit(2);
      }
      return argv[++a];
    };
    if (arg == "--data") {
      data_dir = next();
      dem_dir = (std::filesystem::path(data_dir) / "..").lexically_normal().string();
    } else if (arg == "--case") {
      which = next();
      case_given = true;
    } else if (arg == "--scaling") {
      scaling = true;
    } else if (arg == "--threads") {
      threads.clear();
      std::istringstream is(next());
      std::string t;
      while (std::getline(is, t, ',')) threads.push_back(std::stoi(t));
    } else if (arg == "--quick") {
      quick = true;
    } else if (arg == "--no-peer") {
      no_peer = true;
    } else if (arg == "--shuffle") {
      shuffle = true;
    } else if (arg == "--sort") {
      sort_interval = std::stoi(next());
      sort_given = true;
    } else if (arg == "--profile") {
      profile = true;
    } else if (arg == "--energy") {
      g_energy = true;
    } else if (arg == "--breakage") {
      breakage = true;
    } else if (arg == "--vtk") {
      vtk_dir = next();
    } else {
      std::cerr << "usage: bench_dem_peers [--data DIR] [--case small|large|all] [--threads 1,2] "
                   "[--scaling] [--profile] [--quick] [--vtk DIR] [--no-peer] [--shuffle] "
                   "[--sort N] [--breakage] [--energy]\n"
                   "  --no-peer: do not run LIGGGHTS; ratios use the recorded figures\n"
                   "  --scaling: the large bed on 1, 2, 4, ... threads up to the processors, and "
                   "the speed-up of each over 1 thread\n"
                   "  --profile: where each step's time went, thread by thread\n";
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  if (scaling) {
    const int most = max_threads();
    threads.clear();
    for (int t = 1; t < most; t *= 2) threads.push_back(t);
    threads.push_back(most);
    if (!case_given) which = "large";
    // as a partita run orders its particles (the DEM adapter's sort_interval: 10)
    if (!sort_given) sort_interval = 10;
  }
  for (const int t : threads)
    if (t < 1) {
      std::cerr << "bench_dem_peers: --threads takes counts of at least 1\n";
      return 2;
    }
  const std::vector<Case> cases = {{"small", 0.02, 20000, 4.14, 5.58e6, 1.09e7},
                                   {"large", 0.06, 5000, 4.62, 4.79e6, 9.62e6}};
  const bool liggghts = !no_peer && on_path("liggghts");
  const long warmup = quick ? 100 : 500;
  std::printf("# partita::dem peer benchmark%s; LIGGGHTS %s\n", quick ? " (quick mode)" : "",
              liggghts  ? "on PATH: measured in this run"
              : no_peer ? "not run (--no-peer): recorded figures"
                        : "not on PATH: recorded figures");
  std::printf("# machine shared with other jobs: timings are noisy\n");
  if (shuffle || sort_interval > 0)
    std::printf("# particle order: %s, renumbered in cell order %s\n",
                shuffle ? "shuffled" : "as in the file",
                sort_interval > 0
                    ? ("every " + std::to_string(sort_interval) + " list builds").c_str()
                    : "never");
  std::printf(
      "# psteps/s = N x steps / wall seconds of the timed loop; cpu_s = process CPU time of\n"
      "# the loop (with 1 thread, N x steps / cpu_s estimates an unloaded machine)\n");
  std::printf("%-9s %3s %8s %7s %6s %9s %9s %11s %9s %8s %10s %10s %9s\n", "case", "thr", "N",
              "steps", "builds", "loop_s", "cpu_s", "psteps/s", "cn/atom", "peer_cn", "KE_J",
              "KEtrans_J", "vs_LIGG");
  try {
    for (const Case& c : cases) {
      if (which != "all" && which != c.name) continue;
      const LammpsData data = LammpsData::read(data_dir + "/bed_" + c.name + ".data");
      const long steps = quick ? c.steps / 20 : c.steps;
      std::vector<std::pair<int, double>> rates;  // (threads, particle-steps/s) of the plain runs
      double busy_one = 0.0;  // --profile: busy time per fused step on 1 thread [us]
      for (int nt : threads) {
        double plain_cpu = 0.0, plain_rate = 0.0;
        for (int with_breakage = 0; with_breakage <= (breakage ? 1 : 0); ++with_breakage) {
          set_num_threads(nt);
          System sys = make_system(data, c.width, shuffle, sort_interval, with_breakage == 1);
          const double dt = 1.9e-6;
          sys.run(warmup, dt);
          const auto t0 = std::chrono::steady_clock::now();
          const std::clock_t c0 = std::clock();
          const long builds0 = sys.neighbor_list().build_count();
          const bool profiled = profile && with_breakage == 0;
          sys.set_step_profiling(profiled);
          sys.run(steps, dt);
          const long builds = sys.neighbor_list().build_count() - builds0;
          const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
          const double seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          double ke_trans = 0.0;
          for (std::size_t i = 0; i < sys.particle_count(); ++i)
            ke_trans += 0.5 * sys.particles().mass[i] * sys.particles().velocity[i].squaredNorm();
          const double rate = static_cast<double>(sys.particle_count()) * steps / seconds;
          const double cn = sys.mean_contacts_per_particle();
          // recorded LIGGGHTS figures exist for 1 and 2 ranks only
          double peer = nt == 1 ? c.liggghts_1 : nt == 2 ? c.liggghts_2 : 0.0;
          const char* peer_kind = peer > 0.0 ? "rec" : "";
          if (liggghts && with_breakage == 0) {
            const double measured =
                run_liggghts(dem_dir, c, static_cast<long>(data.size()), nt, steps);
            if (measured > 0.0) peer = measured, peer_kind = "meas";
          }
          const std::string name = c.name + (with_breakage ? "/brk" : "");
          std::printf(
              "%-9s %3d %8zu %7ld %6ld %9.3f %9.3f %11.4g %9.4f %8.2f %10.3g %10.3g %7s "
              "%s%s\n",
              name.c_str(), nt, sys.particle_count(), steps, builds, seconds, cpu, rate, cn,
              c.peer_contacts, sys.kinetic_energy(), ke_trans,
              peer > 0.0 ? fmt_ratio(rate / peer).c_str() : "-", peer_kind,
              // a quick run stops before the bed has settled to the peers' end state
              quick                                         ? "  (quick: contacts not compared)"
              : std::abs(cn / c.peer_contacts - 1.0) > 0.02 ? "  CONTACTS DIFFER >2%"
                                                            : "");
          if (profiled) {
            const System::StepProfile& p = sys.step_profile();
            print_profile(nt, p, busy_one);
            if (nt == 1 && p.fused_steps > 0 && !p.threads.empty())
              busy_one = 1e6 * p.threads[0].busy() / static_cast<double>(p.fused_steps);
          }
          if (with_breakage == 0) {
            plain_cpu = cpu, plain_rate = rate;
            rates.emplace_back(nt, rate);
          } else {
            std::printf(
                "# %s, %d thread(s): breakage enabled, nothing broken (%lld events): "
                "%+.1f %% wall time, %+.1f %% CPU time per step\n",
                c.name.c_str(), nt,
                static_cast<long long>(static_cast<const Breakage&>(sys.hook(0)).counters().events),
                100.0 * (plain_rate / rate - 1.0), 100.0 * (cpu / plain_cpu - 1.0));
          }
          std::fflush(stdout);
          if (!vtk_dir.empty() && with_breakage == 0) {
            std::filesystem::create_directories(vtk_dir);
            partita::adapters::write_particles_vtp(sys, vtk_dir + "/bed_" + c.name + ".vtp", {});
          }
        }
      }
      print_scaling(c.name, rates);
    }
  } catch (const Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const partita::Error& e) {  // writing the --vtk file
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
