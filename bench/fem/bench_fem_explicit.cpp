// bench_fem_explicit: the central-difference (explicit) step of the nonlinear path on a plated
// structure: a steel plate of NX x NY x 1 Hex8 cells (50 x 50 mm cells, 10 mm thick: default
// 320 x 320, 102,400 elements, 16 x 16 m: a hull plate meshed as crash analyses do, 5 t), edges
// clamped, lumped mass, J2 plasticity (E = 210 GPa, nu = 0.3, rho = 7850 kg/m^3, sigma_y =
// 250 MPa, linear hardening E/100). Load: an initial transverse velocity v_z = V sin(2 pi x / L)
// sin(2 pi y / L), L = 8 cells (a bending mode of wavelength 400 mm, zero on the clamped edges),
// V such that the surfaces at its crests reach the yield strain after half the timed steps and
// the untimed one (a strain increment of eps_y / 3 = 2.8e-4 a step at the crests with the default
// 4 timed steps, a surface strain rate of 190/s): in the timed steps
// the plate bends into yield from its surfaces inward around every crest, with the enhanced modes
// of the EAS Hex8 active in every element. dt = 0.9 x the stable step.
//
// Lines (each at 1 and 2 OpenMP threads by default):
//   linear     linear-elastic explicit step (the linear path: K u with the assembled K): the
//              reference of the cost of the element-free part of a step
//   j2-eas     small-strain J2, EAS Hex8 (the nonlinear path's default Hex8; a thin element
//              gets 2 x 2 x 6 points)
//   j2-plain   small-strain J2, plain Hex8 (2 x 2 x 2 points)
//   fj2-eas    finite-strain J2 (j2-plasticity-finite-strain), EAS Hex8 (only when named in
//              --lines: minutes a step at the default size; try 80x80)
//   fj2-plain  finite-strain J2, plain Hex8
//   j2-reduced  small-strain J2, reduced Hex8 (Hex8Formulation::Reduced: one point in the plane,
//              6 through the thickness, hourglass stabilisation; the explicit plate element)
//   fj2-reduced finite-strain J2, reduced Hex8
// Printed per line: element-steps per second (elements x steps / wall seconds of the timed
// steps), points per element, law evaluations per element-step (EAS: points x local passes),
// the share of plastic points at the end, the ratio to the aim (1e6 element-steps/s on 2 cores)
// and to the linear-elastic explicit step. Then, on one thread, where a step's time
// goes: the material law, the element kinematics (F, the element force, the EAS condensation),
// the assembly (the element forces into the global force), the contact (0: no indenter in the
// model) and the rest (integrator update, commit of the histories). The shares come from the
// last step evaluated again with the same state by a MaterialContribution of the bench (its
// phase clocks) and, for the law, its evaluations of that step recorded and replayed (CPU
// seconds of the calling thread throughout, as shares of the last step's: the machine may be
// shared, and the steps differ, as more points yield). Nothing is asserted:
// read the figures as ratios.
//
// usage: bench_fem_explicit [NXxNY] [--steps N] [--threads 1,2] [--lines linear,j2-eas,...]
//                           [--no-shares] [--dump DIR]   (DIR/<line>_<threads>.f64: u at the end)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <time.h>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/material_contribution.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6, kH = kE / 100.0;
constexpr double kCell = 0.05, kThick = 0.01;
constexpr double kAim = 1e6;  // element-steps per second on 2 cores (the aim)

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void set_threads(int t) {
#ifdef _OPENMP
  omp_set_num_threads(t);
#else
  (void)t;
#endif
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// A law that counts its evaluations and records the inputs (F and the committed history) of
// every stride-th of them, for a replay on the CPU clock (one thread).
class RecordingLaw final : public MaterialLaw {
 public:
  explicit RecordingLaw(std::shared_ptr<const MaterialLaw> law) : law_(std::move(law)) {}
  std::string_view name() const override { return law_->name(); }
  double density() const override { return law_->density(); }
  double dilatational_wave_speed() const override { return law_->dilatational_wave_speed(); }
  double bulk_modulus() const override { return law_->bulk_modulus(); }
  bool small_strain() const override { return law_->small_strain(); }
  int state_size() const override { return law_->state_size(); }
  void initialise_state(std::span<double> state) const override { law_->initialise_state(state); }
  void evaluate(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                MaterialResponse& response) const override {
    record(f, committed, true);
    law_->evaluate(f, committed, trial, response);
  }
  void evaluate_stress(const Mat3& f, std::span<const double> committed, std::span<double> trial,
                       MaterialResponse& response) const override {
    record(f, committed, false);
    law_->evaluate_stress(f, committed, trial, response);
  }
  double plastic_work_density(std::span<const double> state) const override {
    return law_->plastic_work_density(state);
  }
  double equivalent_plastic_strain(std::span<const double> state) const override {
    return law_->equivalent_plastic_strain(state);
  }
  void reset(std::size_t stride) const {
    stride_ = std::max<std::size_t>(1, stride);
    calls_ = 0;
    f_.clear();
    committed_.clear();
    tangent_.clear();
  }
  std::size_t calls() const { return calls_; }
  // CPU seconds of one evaluation, the recorded ones replayed
  double replay_seconds_per_call() const {
    const std::size_t n = f_.size(), ns = static_cast<std::size_t>(law_->state_size());
    if (n == 0) return 0.0;
    std::vector<double> trial(ns);
    MaterialResponse r;
    double sink = 0.0;
    const double c0 = thread_cpu_seconds();
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = std::span<const double>(committed_).subspan(i * ns, ns);
      if (tangent_[i] != 0) {
        law_->evaluate(f_[i], c, trial, r);
      } else {
        law_->evaluate_stress(f_[i], c, trial, r);
      }
      sink += r.stress(0, 0);
    }
    const double cpu = thread_cpu_seconds() - c0;
    volatile double keep = sink;
    (void)keep;
    return cpu / static_cast<double>(n);
  }

 private:
  void record(const Mat3& f, std::span<const double> committed, bool tangent) const {
    if (calls_ % stride_ == 0) {
      f_.push_back(f);
      committed_.insert(committed_.end(), committed.begin(), committed.end());
      tangent_.push_back(tangent ? 1 : 0);
    }
    ++calls_;
  }
  std::shared_ptr<const MaterialLaw> law_;
  mutable std::size_t stride_ = 1, calls_ = 0;
  mutable std::vector<Mat3> f_;
  mutable std::vector<double> committed_;
  mutable std::vector<char> tangent_;
};

struct Line {
  std::string name;
  bool linear = false, finite = false, eas = false;
  bool by_default = true;
  bool reduced = false;  // the reduced Hex8 (Hex8Formulation::Reduced)
};

// fj2-eas only when named: its law's tangent (18 return maps a point, the EAS local Newton
// needs it) makes a step of 10^5 elements take minutes
const std::vector<Line> kLines = {{"linear", true, false, false, true},
                                  {"j2-eas", false, false, true, true},
                                  {"j2-plain", false, false, false, true},
                                  {"j2-reduced", false, false, false, true, true},
                                  {"fj2-eas", false, true, true, false},
                                  {"fj2-plain", false, true, false, true},
                                  {"fj2-reduced", false, true, false, true, true}};

std::shared_ptr<const MaterialLaw> make_law(const Line& line) {
  if (line.finite)
    return std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
  return std::make_shared<J2PlasticityLaw>(kE, kNu, kRho, HardeningCurve::linear(kSy, kH));
}

Model plate_model(int nx, int ny, const Line& line, std::shared_ptr<const MaterialLaw> law) {
  Mesh mesh = make_box_mesh(
      {Vec3::Zero(), Vec3(nx * kCell, ny * kCell, kThick), {nx, ny, 1}, ElementType::Hex8});
  Model model(mesh, Material{kE, kNu, kRho});
  if (!line.linear) model.set_material_law(std::move(law));
  model.set_hex8_formulation(line.reduced                ? Hex8Formulation::Reduced
                             : line.eas || line.linear ? Hex8Formulation::IncompatibleModes
                                                       : Hex8Formulation::Full);
  for (const char* edge : {"xmin", "xmax", "ymin", "ymax"}) model.fix(edge);
  return model;
}

SolverOptions explicit_options() {
  SolverOptions o;
  o.integrator = Integrator::CentralDifference;
  o.mass = MassType::Lumped;
  return o;
}

// The initial velocity field (see the header): V from the bending strain rate at the crests.
Eigen::VectorXd initial_velocity(const Mesh& mesh, double dt, int steps) {
  const double wavelength = 8.0 * kCell, k = 2.0 * std::numbers::pi / wavelength;
  // surface strain rate at a crest (t/2) k^2 V in x and in y (equibiaxial, plane stress: yield
  // at eps = sigma_y (1 - nu) / E); reached after half the timed steps (the untimed first one
  // included), at least 1.5
  const double eps_y = kSy * (1.0 - kNu) / kE;
  const double v = eps_y / (0.5 * kThick * k * k * std::max(1.5, 0.5 * steps + 1.0) * dt);
  Eigen::VectorXd vel = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(mesh.num_nodes()));
  for (std::size_t n = 0; n < mesh.num_nodes(); ++n) {
    const Vec3 x = mesh.node(n);
    vel[3 * static_cast<Eigen::Index>(n) + 2] = v * std::sin(k * x[0]) * std::sin(k * x[1]);
  }
  return vel;
}

// FNV-1a of the bits of u, v and the committed histories: equal hashes, equal results.
std::uint64_t state_hash(const SolverState& s) {
  std::uint64_t h = 1469598103934665603ull;
  auto add = [&](const double* p, std::size_t n) {
    const auto* b = reinterpret_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  add(s.displacement.data(), static_cast<std::size_t>(s.displacement.size()));
  add(s.velocity.data(), static_cast<std::size_t>(s.velocity.size()));
  add(s.material_state.data(), s.material_state.size());
  return h;
}

struct Run {
  std::uint64_t hash = 0;
  double step_seconds = 0.0, step_cpu = 0.0;  // per timed step (cpu: the calling thread's)
  double last_step_cpu = 0.0;                  // of the last one (the shares re-evaluate it)
  double step_process_cpu = 0.0;               // per timed step, all threads of the process
  double plastic_share = 0.0;
  SolverState before_last;  // the state before the last timed step (for the shares)
  Eigen::VectorXd u_last;   // the displacement after it
  Eigen::VectorXd u;        // the displacement at the end
};

Run run(const Model& model, double dt, int steps, bool keep_state) {
  StructuralSolver solver(model, explicit_options());
  SolverState s = solver.save_state();
  s.velocity = initial_velocity(model.mesh(), dt, steps);
  s.acceleration_valid = false;
  solver.restore_state(s);
  solver.step(dt);  // untimed: the initial acceleration, first touch of the buffers
  Run r;
  const auto t0 = Clock::now();
  const double c0 = thread_cpu_seconds();
  const std::clock_t p0 = std::clock();
  double saving = 0.0, saving_cpu = 0.0;  // the copy of the state before the last step: untimed
  for (int i = 0; i < steps; ++i) {
    if (keep_state && i + 1 == steps) {
      const auto ts = Clock::now();
      const double cs = thread_cpu_seconds();
      r.before_last = solver.save_state();
      saving_cpu = thread_cpu_seconds() - cs;
      saving = since(ts);
    }
    const double cs = thread_cpu_seconds();
    solver.step(dt);
    r.last_step_cpu = thread_cpu_seconds() - cs;
  }
  r.step_cpu = (thread_cpu_seconds() - c0 - saving_cpu) / steps;
  r.step_process_cpu =
      (static_cast<double>(std::clock() - p0) / CLOCKS_PER_SEC - saving_cpu) / steps;
  r.step_seconds = (since(t0) - saving) / steps;
  r.hash = state_hash(solver.save_state());
  r.u = solver.displacement();
  if (keep_state) r.u_last = solver.displacement();
  const Eigen::VectorXd eqps = solver.equivalent_plastic_strain();
  if (eqps.size() > 0) {
    r.plastic_share = static_cast<double>((eqps.array() > 0.0).count()) /
                      static_cast<double>(eqps.size());
  }
  return r;
}

struct Options {
  int nx = 320, ny = 320, steps = 4;
  std::vector<int> threads = {1, 2};
  std::vector<std::string> lines;
  bool shares = true;
  std::string dump;  // folder: u after the timed steps of each line and thread count, raw doubles
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// Where the time of the last step went (1 thread): re-evaluates it with MaterialContributions
// of the bench at the state before it.
struct Shares {
  double law = 0.0, kinematics = 0.0, assembly = 0.0, rest = 0.0;
  double law_calls_per_element = 0.0;
};

// On a shared machine the wall clock counts the time other processes hold the core, so the
// shares are CPU seconds of the calling thread (one thread): of the step, of the material's
// add() at the last step's state (split into the element loop and the assembly by its phase
// clocks), and of the law (its recorded evaluations replayed, times its evaluations).
Shares shares_of(const Model& model, const Line& line, const Run& r, int repeats) {
  Shares sh;
  const double ne = static_cast<double>(model.mesh().num_elements());
  BlockAssembler assembler(model.mesh());
  Eigen::VectorXd f(r.u_last.size());
  double add_cpu = 1e300, f_elements = 0.0, f_assembly = 0.0;
  {
    MaterialContribution mc(model);
    for (int i = 0; i < repeats; ++i) {
      mc.set_committed_state(r.before_last.material_state);
      f.setZero();
      const auto t0 = Clock::now();
      const double c0 = thread_cpu_seconds();
      mc.add(r.u_last, f, nullptr, assembler);
      const double cpu = thread_cpu_seconds() - c0, wall = since(t0);
      if (cpu < add_cpu) {
        add_cpu = cpu;
        f_elements = mc.last_add_seconds().elements / wall;
        f_assembly = mc.last_add_seconds().assembly / wall;
      }
    }
  }
  auto recording = std::make_shared<RecordingLaw>(make_law(line));
  Model recording_model = model;
  recording_model.set_material_law(recording);
  double law_cpu = 1e300;
  {
    MaterialContribution mc(recording_model);
    // once to count the calls (recording only the first), once recording about 2e5 of them
    // spread over the step
    for (int pass = 0; pass < 2; ++pass) {
      recording->reset(pass == 0 ? std::numeric_limits<std::size_t>::max()
                                 : std::max<std::size_t>(1, recording->calls() / 200000));
      mc.set_committed_state(r.before_last.material_state);
      f.setZero();
      mc.add(r.u_last, f, nullptr, assembler);
    }
    sh.law_calls_per_element = static_cast<double>(recording->calls()) / ne;
    for (int i = 0; i < repeats; ++i) {
      law_cpu = std::min(law_cpu, recording->replay_seconds_per_call() *
                                      static_cast<double>(recording->calls()));
    }
  }
  const double step = r.last_step_cpu;
  sh.law = law_cpu / step;
  sh.kinematics = (f_elements * add_cpu - law_cpu) / step;
  sh.assembly = f_assembly * add_cpu / step;
  sh.rest = 1.0 - (f_elements + f_assembly) * add_cpu / step;
  return sh;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--steps") {
      opt.steps = std::max(1, std::atoi(value().c_str()));
    } else if (a == "--threads") {
      opt.threads.clear();
      for (const auto& t : split(value())) opt.threads.push_back(std::max(1, std::atoi(t.c_str())));
    } else if (a == "--lines") {
      opt.lines = split(value());
    } else if (a == "--dump") {
      opt.dump = value();
    } else if (a == "--no-shares") {
      opt.shares = false;
    } else if (a == "-h" || a == "--help") {
      std::printf(
          "usage: bench_fem_explicit [NXxNY] [--steps N] [--threads 1,2] "
          "[--lines linear,j2-eas,j2-plain,j2-reduced,fj2-eas,fj2-plain,fj2-reduced] [--no-shares] [--dump DIR]\n");
      return 0;
    } else if (std::sscanf(a.c_str(), "%dx%d", &opt.nx, &opt.ny) == 2 && opt.nx > 0 &&
               opt.ny > 0) {
    } else {
      std::fprintf(stderr, "unknown argument '%s' (try --help)\n", a.c_str());
      return 2;
    }
  }
  std::vector<Line> lines;
  for (const auto& l : kLines) {
    if ((opt.lines.empty() && l.by_default) ||
        std::find(opt.lines.begin(), opt.lines.end(), l.name) != opt.lines.end())
      lines.push_back(l);
  }
  for (const auto& n : opt.lines) {
    if (std::none_of(kLines.begin(), kLines.end(), [&](const Line& l) { return l.name == n; })) {
      std::fprintf(stderr, "unknown line '%s' (linear, j2-eas, j2-plain, j2-reduced, fj2-eas, fj2-plain, fj2-reduced)\n",
                   n.c_str());
      return 2;
    }
  }
  const long ne = static_cast<long>(opt.nx) * opt.ny;
  std::printf(
      "== explicit step: steel plate %dx%dx1 Hex8 (%ld elements, %.2f x %.2f x %.3f m), J2, "
      "%d timed steps\n",
      opt.nx, opt.ny, ne, opt.nx * kCell, opt.ny * kCell, kThick, opt.steps);

  // the stable step of the cell (the same for every mesh of these cells): from a small plate
  double dt = 1e300;
  for (const auto& l : lines) {
    StructuralSolver small(plate_model(8, 8, l, make_law(l)), explicit_options());
    dt = std::min(dt, 0.9 * small.stable_time_step());
  }
  std::printf("   dt = %.4g s (0.9 x the stable step of the cell)\n\n", dt);
  std::printf("  %-10s %7s %7s %11s %6s %12s %9s %9s %8s %9s  %s\n", "line", "threads",
              "pts/el", "el-steps/s", "(cpu)", "per cpu-s", "step ms", "plastic", "vs aim",
              "vs linear", "hash of u, v, histories");
  double linear_rate[3] = {0.0, 0.0, 0.0};
  struct ShareLine {
    std::string name;
    Shares shares;
  };
  std::vector<ShareLine> share_lines;
  for (const auto& l : lines) {
    const Model model = plate_model(opt.nx, opt.ny, l, make_law(l));
    // points per element: those of a 2 x 2 plate of the same cells (the linear path: 2x2x2)
    double pts = 8.0;
    if (!l.linear) {
      const MaterialContribution small(plate_model(2, 2, l, make_law(l)));
      pts = static_cast<double>(small.num_quadrature_points()) / 4.0;
    }
    Run one;
    for (int t : opt.threads) {
      set_threads(t);
      const bool keep = opt.shares && !l.linear && t == 1;
      Run r = run(model, dt, opt.steps, keep);
      const double rate = static_cast<double>(ne) / r.step_seconds;
      if (l.linear && t <= 2) linear_rate[t] = rate;
      const double lin = t <= 2 ? linear_rate[t] : 0.0;
      char vs_linear[32] = "-";
      if (!l.linear && lin > 0.0) std::snprintf(vs_linear, sizeof vs_linear, "%.3f", rate / lin);
      char per_cpu[32] = "-";
      std::snprintf(per_cpu, sizeof per_cpu, "%.3g",
                    static_cast<double>(ne) / (t == 1 ? r.step_cpu : r.step_process_cpu));
      std::printf("  %-10s %7d %7.0f %11.3g %6.2f %12s %9.2f %8.1f%% %8.3f %9s  %016llx\n",
                  l.name.c_str(), t, pts, rate, r.step_cpu / r.step_seconds, per_cpu,
                  1e3 * r.step_seconds, 100.0 * r.plastic_share, rate / kAim, vs_linear,
                  static_cast<unsigned long long>(r.hash));
      std::fflush(stdout);
      if (!opt.dump.empty()) {
        const std::string path = opt.dump + "/" + l.name + "_" + std::to_string(t) + ".f64";
        if (std::FILE* out = std::fopen(path.c_str(), "wb")) {
          std::fwrite(r.u.data(), sizeof(double), static_cast<std::size_t>(r.u.size()), out);
          std::fclose(out);
        }
      }
      if (keep) one = std::move(r);
    }
    if (opt.shares && !l.linear && one.u_last.size() > 0) {
      set_threads(1);
      share_lines.push_back({l.name, shares_of(model, l, one, 2)});
    }
  }
  if (!share_lines.empty()) {
    std::printf(
        "\n  where a step goes (1 thread, share of the step's CPU time; law evaluations per "
        "element-step)\n");
    std::printf("  %-10s %8s %8s %11s %9s %8s %8s\n", "line", "laws/el", "law", "kinematics",
                "assembly", "contact", "rest");
    for (const auto& s : share_lines) {
      std::printf("  %-10s %8.1f %7.1f%% %10.1f%% %8.1f%% %7.1f%% %7.1f%%\n", s.name.c_str(),
                  s.shares.law_calls_per_element, 100.0 * s.shares.law,
                  100.0 * s.shares.kinematics, 100.0 * s.shares.assembly, 0.0,
                  100.0 * s.shares.rest);
    }
  }
  std::printf(
      "\n  (cpu): the main thread's CPU over wall seconds (below 1 on 1 thread: other processes); "
      "per cpu-s: element-steps per CPU second (1 thread: the calling thread's CPU, the rate on an idle core; more threads: all threads' CPU, with OMP_WAIT_POLICY=PASSIVE so that waiting threads do not count: near the 1-thread figure when the split adds no work); vs aim: element-steps/s over 1e6 (the aim: 10^6 on 2 cores); vs linear: over the "
      "linear-elastic explicit step (the linear path, K u) on as many threads; contact: no "
      "indenter in the model\n");
  return 0;
}
