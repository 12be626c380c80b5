// bench_fem_plate: the seed plate (20 x 20 x 2 mm steel, E = 250 GPa, nu = 0.3, rho = 7850;
// lateral-face nodes fixed in x, y; four bottom corners fixed in z; 10 kPa on the top face),
// C3D8-like Hex8 meshes as in the CalculiX peer decks (shared/bench/peers/fem/gen_plate.py).
// Static: reaction of the corners (4 N). Transient: load applied at t = 0 and held, undamped,
// dt = 1e-6 s, 100 steps. Prints assembly, factorisation and per-step times, and the per-step
// ratio to CalculiX: run live (same invocation) when `ccx` is on PATH, else the recorded
// figures of shared/bench/peers/RESULTS.md (0.155 s/increment at 20x20x2, 2.28 s at 40x40x4).
//
// usage: bench_fem_plate [NXxNYxNZ ...] [--steps N] [--dt S] [--qm6] [--lumped] [--no-ccx]
//                        [--peers DIR] [--backends
//                        eigen-ldlt,cholmod-nesdis,cholmod-nesdis-t,cholmod-nesdis-tf,
//                        cholmod-metis,cholmod-amd,cholmod-amd-tf]
//                        [--no-static]   (transient only: the large plates)
// Each mesh is solved with every linear solver built in (Eigen's SimplicialLDLT + AMD; CHOLMOD
// supernodal with NESDIS, METIS and AMD orderings, solved by CHOLMOD; cholmod-nesdis-t: NESDIS
// solved by the threaded supernodal solve, on all OpenMP threads; cholmod-nesdis-tf and
// cholmod-amd-tf: CHOLMOD's analysis with that ordering, partita's threaded supernodal
// factorisation and the threaded solve, on all OpenMP threads), and the summary prints their
// factorisation and step times as ratios to the first one listed, and to CalculiX. Timings are
// wall-clock on a possibly shared machine: read them with that caveat.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/linear_solver.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Options {
  std::vector<std::array<int, 3>> meshes;
  int steps = 100;
  double dt = 1e-6;
  bool qm6 = false, lumped = false, ccx = true;
  std::vector<std::string> backends;  // empty: all built in
  bool with_static = true;
  std::string peers = PARTITA_PEERS_DIR;
};

Model plate_model(std::array<int, 3> cells, bool qm6) {
  const double lx = 0.02, ly = 0.02, lz = 0.002;
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(lx, ly, lz), cells, ElementType::Hex8});
  mesh.add_node_set_where("lateral", [&](const Vec3& x) {
    const double tol = 1e-12;
    return x[0] < tol || x[0] > lx - tol || x[1] < tol || x[1] > ly - tol;
  });
  mesh.add_node_set_where("corners", [&](const Vec3& x) {
    const double tol = 1e-12;
    return x[2] < tol && (x[0] < tol || x[0] > lx - tol) && (x[1] < tol || x[1] > ly - tol);
  });
  Model model(mesh, Material{250e9, 0.3, 7850});
  model.set_hex8_formulation(qm6 ? Hex8Formulation::IncompatibleModes : Hex8Formulation::Full);
  model.fix("lateral", {0, 1});
  model.fix("corners", {2});
  model.add_pressure("zmax", 10e3);
  return model;
}

std::string find_on_path(const std::string& exe) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    const auto p = std::filesystem::path(dir) / exe;
    std::error_code ec;
    if (std::filesystem::is_regular_file(p, ec)) return p.string();
  }
  return {};
}

// Runs the CalculiX dynamic deck for this mesh; returns seconds per increment, or < 0.
double run_ccx(const Options& opt, std::array<int, 3> c) {
  const std::string gen = opt.peers + "/fem/gen_plate.py";
  if (!std::filesystem::exists(gen)) {
    std::cout << "  ccx: " << gen << " not found, using recorded figures\n";
    return -1.0;
  }
  const auto dir = std::filesystem::temp_directory_path() /
                   ("bench_fem_plate_ccx_" +
                    std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  std::filesystem::create_directories(dir);
  const std::string tag =
      "plate_" + std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" + std::to_string(c[2]);
  char dt[32];
  std::snprintf(dt, sizeof dt, "%g", opt.dt);
  const std::string generate = "python3 '" + gen + "' " + std::to_string(c[0]) + " " +
                               std::to_string(c[1]) + " " + std::to_string(c[2]) + " '" +
                               dir.string() + "' " + dt + " " + std::to_string(opt.steps) +
                               " 2>/dev/null";
  if (std::system(generate.c_str()) != 0) {
    std::cout << "  ccx: deck generation failed, using recorded figures\n";
    return -1.0;
  }
  const std::string deck = tag + "_dynamic_n" + std::to_string(opt.steps);
  const std::string run =
      "cd '" + dir.string() +
      "' && OMP_NUM_THREADS=1 CCX_NPROC_EQUATION_SOLVER=1 CCX_NPROC_STIFFNESS=1 "
      "CCX_NPROC_RESULTS=1 ccx -i " +
      deck + " > ccx.log 2>&1";
  const auto t0 = Clock::now();
  const int rc = std::system(run.c_str());
  const double wall = since(t0);
  std::filesystem::remove_all(dir);
  if (rc != 0) {
    std::cout << "  ccx: run failed (exit " << rc << "), using recorded figures\n";
    return -1.0;
  }
  std::cout << "  ccx (live, 1 thread): " << wall << " s for " << opt.steps << " increments\n";
  return wall / opt.steps;
}

struct Backend {
  std::string name;  // eigen-ldlt, cholmod-nesdis, cholmod-nesdis-t, cholmod-nesdis-tf, ...
  LinearSolver solver;
  FillOrdering ordering;
  SolveThreading threading = SolveThreading::Serial;  // CHOLMOD's solve or the threaded one
  FactorThreading factor = FactorThreading::Serial;   // CHOLMOD's factorisation or partita's
};

std::vector<Backend> all_backends() {
  std::vector<Backend> b = {{"eigen-ldlt", LinearSolver::EigenLdlt, FillOrdering::Automatic}};
  if (cholmod_available()) {
    b.push_back({"cholmod-nesdis", LinearSolver::Cholmod, FillOrdering::Nesdis});
    b.push_back({"cholmod-nesdis-t", LinearSolver::Cholmod, FillOrdering::Nesdis,
                 SolveThreading::Threaded});
    b.push_back({"cholmod-nesdis-tf", LinearSolver::Cholmod, FillOrdering::Nesdis,
                 SolveThreading::Threaded, FactorThreading::Threaded});
    b.push_back({"cholmod-metis", LinearSolver::Cholmod, FillOrdering::Metis});
    b.push_back({"cholmod-amd", LinearSolver::Cholmod, FillOrdering::Amd});
    b.push_back({"cholmod-amd-tf", LinearSolver::Cholmod, FillOrdering::Amd,
                 SolveThreading::Threaded, FactorThreading::Threaded});
  }
  return b;
}

struct Result {
  double static_factorisation = 0.0, nnz_l = 0.0, per_step = 0.0, amortised = 0.0;
  double per_step_cpu = 0.0;  // process CPU time per steady step (less noisy when shared)
  double transient_factorisation = 0.0;
  Eigen::VectorXd u_static, u_transient;
};

Result bench_backend(const Options& opt, const Model& model, const Backend& b) {
  Result res;
  // static
  if (opt.with_static) {
    SolverOptions so;
    so.linear_solver = b.solver;
    so.fill_ordering = b.ordering;
    so.solve_threading = b.threading;
    so.factor_threading = b.factor;
    const auto t0 = Clock::now();
    StructuralSolver s(model, so);
    const double t_setup = since(t0);
    const auto t1 = Clock::now();
    s.solve_static();
    const double t_solve = since(t1);
    const Vec3 r = s.reaction("corners");
    res.static_factorisation = s.timings().factorisation;
    res.nnz_l = s.timings().factor_nonzeros;
    res.u_static = s.displacement();
    std::printf(
        "  [%s] static: %zu dofs, set-up (assembly) %.3f s, factorise + solve %.3f s "
        "(factorisation %.3f s, nnz(L) %.3g), Rz = %.9f N (p A = 4 N)\n",
        b.name.c_str(), s.num_dofs(), t_setup, t_solve, res.static_factorisation, res.nnz_l, r[2]);
  }
  // transient
  SolverOptions so;
  so.mass = opt.lumped ? MassType::Lumped : MassType::Consistent;
  so.linear_solver = b.solver;
  so.fill_ordering = b.ordering;
  so.solve_threading = b.threading;
  so.factor_threading = b.factor;
  const auto t0 = Clock::now();
  StructuralSolver s(model, so);
  double rmin = 1e300, rmax = -1e300, rlast = 0.0;
  double first_step = 0.0, later_steps = 0.0, later_cpu = 0.0;
  for (int k = 0; k < opt.steps; ++k) {
    const auto ts = Clock::now();
    const std::clock_t cs = std::clock();
    s.step(opt.dt);
    if (k > 0) later_cpu += static_cast<double>(std::clock() - cs) / CLOCKS_PER_SEC;
    (k == 0 ? first_step : later_steps) += since(ts);
    const double r = s.reaction("corners")[2];
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
    rlast = r;
  }
  const double total = since(t0);
  const auto& tm = s.timings();
  res.per_step = opt.steps > 1 ? later_steps / (opt.steps - 1) : first_step;
  res.per_step_cpu = opt.steps > 1 ? later_cpu / (opt.steps - 1) : 0.0;
  res.amortised = (tm.assembly + tm.factorisation + tm.solve) / opt.steps;
  res.transient_factorisation = tm.factorisation;
  res.nnz_l = tm.factor_nonzeros;
  res.u_transient = s.displacement();
  std::printf(
      "  [%s] transient (%s mass, dt = %g s, %d steps): assembly K+M %.3f s, K_eff factorised "
      "%zu x in %.3f s, per step %.2f ms (steady), first step %.3f s, total %.3f s; corner Rz "
      "min %.3f max %.3f last %.3f N\n",
      b.name.c_str(), opt.lumped ? "lumped" : "consistent", opt.dt, opt.steps, tm.assembly,
      tm.factorisations, tm.factorisation, 1e3 * res.per_step, first_step, total, rmin, rmax,
      rlast);
  return res;
}

void bench(const Options& opt, std::array<int, 3> cells) {
  const std::string tag =
      std::to_string(cells[0]) + "x" + std::to_string(cells[1]) + "x" + std::to_string(cells[2]);
  std::printf("\n== plate %s Hex8 (%s), %d elements\n", tag.c_str(),
              opt.qm6 ? "incompatible modes" : "full integration, as C3D8",
              cells[0] * cells[1] * cells[2]);
  const Model model = plate_model(cells, opt.qm6);

  std::vector<Backend> backends;
  for (const auto& b : all_backends()) {
    if (opt.backends.empty() ||
        std::find(opt.backends.begin(), opt.backends.end(), b.name) != opt.backends.end())
      backends.push_back(b);
  }
  std::vector<Result> results;
  for (const auto& b : backends) results.push_back(bench_backend(opt, model, b));

  const std::map<std::string, double> recorded = {{"20x20x2", 0.155}, {"40x40x4", 2.28}};
  double ccx = -1.0;
  if (opt.ccx && !find_on_path("ccx").empty()) ccx = run_ccx(opt, cells);
  std::string source = "live";
  if (ccx < 0.0) {
    const auto it = recorded.find(tag);
    if (it != recorded.end()) {
      ccx = it->second;
      source = "recorded, RESULTS.md";
    }
  }
  // summary: ratios to the first backend (eigen-ldlt when listed) and to CalculiX
  std::printf("  %-16s %10s %10s %10s %9s %16s %12s %10s\n", "backend", "factorise s", "nnz(L)",
              "step ms", "(cpu ms)", "vs " /* first */, "ccx/partita", "|du|/|u|");
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    const auto& r0 = results.front();
    const double du =
        opt.with_static ? (r.u_static - r0.u_static).norm() / r0.u_static.norm() : 0.0;
    const double dv = (r.u_transient - r0.u_transient).norm() / r0.u_transient.norm();
    char vs[64], cx[32];
    const double f0 = opt.with_static ? r0.static_factorisation : r0.transient_factorisation;
    const double f = opt.with_static ? r.static_factorisation : r.transient_factorisation;
    std::snprintf(vs, sizeof vs, "%.1fx/%.1fx/%.1fx", f0 / f, r0.per_step / r.per_step,
                  r0.per_step_cpu / r.per_step_cpu);
    if (ccx > 0.0)
      std::snprintf(cx, sizeof cx, "%.0fx", ccx / r.per_step);
    else
      std::snprintf(cx, sizeof cx, "-");
    std::printf("  %-16s %10.3f %10.3g %10.2f %9.2f %16s %12s %10.1e\n", backends[i].name.c_str(),
                f, r.nnz_l, 1e3 * r.per_step, 1e3 * r.per_step_cpu, vs, cx, std::max(du, dv));
  }
  std::printf(
      "  (factorise: of K (static) or, with --no-static, of K_eff; vs: speed-up over %s of "
      "that factorisation / of the steady step (wall) / (CPU); |du|/|u|: largest "
      "relative difference of the static and final transient displacements to it)\n",
      backends.front().name.c_str());
  if (ccx > 0.0)
    std::printf("  CalculiX %.3f s/increment (%s, 1 thread)\n", ccx, source.c_str());
  else
    std::printf("  no CalculiX figure for this mesh (ccx not on PATH, none recorded)\n");
}

}  // namespace

int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

int main(int argc, char** argv) {
  Options opt;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--steps")
        opt.steps = std::stoi(value());
      else if (a == "--dt")
        opt.dt = std::stod(value());
      else if (a == "--qm6")
        opt.qm6 = true;
      else if (a == "--lumped")
        opt.lumped = true;
      else if (a == "--no-ccx")
        opt.ccx = false;
      else if (a == "--peers")
        opt.peers = value();
      else if (a == "--no-static")
        opt.with_static = false;
      else if (a == "--backends") {
        std::stringstream list(value());
        std::string name;
        while (std::getline(list, name, ',')) opt.backends.push_back(name);
      } else if (a == "-h" || a == "--help") {
        std::cout << "usage: bench_fem_plate [NXxNYxNZ ...] [--steps N] [--dt S] [--qm6] "
                     "[--lumped] [--no-ccx] [--peers DIR] [--backends "
                     "eigen-ldlt,cholmod-nesdis,cholmod-nesdis-t,cholmod-nesdis-tf,cholmod-metis,"
                     "cholmod-amd,cholmod-amd-tf] "
                     "[--no-static]\n";
        return 0;
      } else {
        std::array<int, 3> c{};
        if (std::sscanf(a.c_str(), "%dx%dx%d", &c[0], &c[1], &c[2]) != 3)
          throw std::runtime_error("unknown argument " + a);
        opt.meshes.push_back(c);
      }
    }
    if (opt.meshes.empty()) opt.meshes = {{20, 20, 2}, {40, 40, 4}};
    std::printf(
        "bench_fem_plate: seed plate, %d steps of %g s. Wall-clock timings on a possibly shared "
        "machine. OpenMP threads: %d (cholmod-nesdis-t's solve and the assembly); threaded-solve "
        "kernels: %s\n",
        opt.steps, opt.dt, max_threads(), threaded_solve_kernels().c_str());
    for (const auto& c : opt.meshes) bench(opt, c);
  } catch (const std::exception& e) {
    std::cerr << "bench_fem_plate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
