// A split bed on MPI ranks (MpiSubdomainTransport, one subdomain a rank) steps to the bits of the
// same bed in one subdomain in one process:
//   mpirun -n N partita_dem_mpi_subdomains BED [--deadline S] [--piece BYTES]
//                                              [--stall RANK STEP SECONDS] [--no-ghosts]
//                                              [--restart WRITERS READERS STEP FILE]
// BED: gravity (a polydisperse bed thrown about in a closed box under gravity), pressed (a bed
// pressed by a plate mesh moved and deformed every step, squeezed by a moving side plane) or
// crossing (a long box whose particles fly along it at up to 1.8 m/s: many cross the cuts).
// Every rank builds the same bed, keeps the particles its box of a bisection into N owns and
// steps them with SubdomainStepper; every particle's id, x, v, omega and every rank's collective
// sums (kinetic and elastic energy, the contacts, momentum, the walls' forces, each at once and
// all in one round, the planes' forces, the mesh's force, per triangle and per vertex, the energy
// books and their balance) go to
// rank 0 (through the transport), which steps the bed in one subdomain
// (InProcessTransport) and compares them bit for bit: exit status 1 and a message on the first
// difference. --piece: the largest MPI message of the transport (cut and joined). --stall: rank
// RANK sleeps SECONDS before step STEP; the others must end the run past the deadline (--deadline,
// seconds) with a message naming it (exit status 3, MPI_Abort). --no-ghosts: the split without
// ghosts (SubdomainStepper::Options::ghost_distance 0), whose bits must differ (the comparison
// can fail). --restart (on max(WRITERS, READERS) ranks): the first WRITERS ranks step the bed to
// step STEP and gather its SplitRestart to rank 0, which writes the stream to FILE; the first
// READERS ranks read it, each restores it (rank 0 takes the particles, resume() sends them to
// their owners) and they step on to the end: the bits of one subdomain written and resumed in one
// process (a resumed run may differ from an uninterrupted one in the last bits: subdomain.hpp).

#include "../subdomain_beds.hpp"

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/mpi_transport.hpp"
#include "partita/dem/subdomain.hpp"
#include "partita/dem/system.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <mpi.h>

using namespace partita::dem;

namespace {

// ---- the beds --------------------------------------------------------------------------------

struct Bed {
  Eigen::Vector3d lo, hi;          // the box of planes
  Eigen::Vector3d cut_hi;          // the decomposition's bounds: [lo, cut_hi]
  double skin = 0.0;
  long steps = 0;
  std::shared_ptr<test::ThrownBed> particles;  // (shared with the set-up functions)
  std::function<std::unique_ptr<System>(const std::vector<int>&)> system;  // the particles kept
  std::function<void(System&, long step, double dt)> before_step;          // moves the meshes
  long min_migrated = 1;  // on several ranks, at least this many particles change rank
};


// The set-up of a bed in a closed box of planes with friction under gravity.
std::function<std::unique_ptr<System>(const std::vector<int>&)> closed_box(const Bed& bed) {
  return [lo = bed.lo, hi = bed.hi, b = bed.particles](const std::vector<int>& keep) {
    auto sys = std::make_unique<System>();
    const int m = sys->add_material({1.0e7, 0.3, 2500.0});
    sys->add_interaction(m, m, {0.5, 0.5, 0.05});
    sys->set_gravity({0, 0, -9.81});
    test::add_bed_particles(*sys, *b, keep, m);
    sys->add_box(lo, hi, m);
    return sys;
  };
}

// The bed thrown about in a closed box under gravity (test_subdomains.cpp's bed).
Bed gravity_bed() {
  Bed bed;
  bed.lo = Eigen::Vector3d::Zero();
  bed.hi = Eigen::Vector3d(8e-3, 8e-3, 18e-3);
  bed.cut_hi = bed.hi;
  bed.skin = 0.05e-3;
  bed.steps = 300;
  bed.particles = std::make_shared<test::ThrownBed>(
      test::thrown_bed(bed.lo, bed.hi, 11, 0x9e3779b97f4a7c15ull));
  bed.system = closed_box(bed);
  return bed;
}

// A box 24 mm long (x) and 6 mm wide whose first half holds the particles, thrown as one at 3 m/s
// along x (and about, as the others): the bed flies down the box, across the cuts of a bisection
// of the starting positions (cuts along x, all in the first half), and piles up at the far end.
Bed crossing_bed() {
  Bed bed;
  bed.lo = Eigen::Vector3d::Zero();
  bed.hi = Eigen::Vector3d(24e-3, 6e-3, 6e-3);
  bed.cut_hi = bed.hi;
  bed.skin = 0.05e-3;
  bed.steps = 300;
  bed.particles = std::make_shared<test::ThrownBed>(
      test::thrown_bed(bed.lo, Eigen::Vector3d(12e-3, 6e-3, 6e-3), 23, 0x5851f42d4c957f2dull));
  bed.particles->v.col(0).array() += 3.0;
  bed.system = closed_box(bed);
  return bed;
}

// A bed pressed by a plate mesh going down and sagging, squeezed by a moving +x plane
// (test_subdomain_meshes.cpp's bed): the box without its +x face (wall 0), the plane (wall 1),
// the plate (mesh 0) moved before every step.
Bed pressed_bed() {
  constexpr double width = 12e-3;
  Bed bed;
  bed.lo = Eigen::Vector3d::Zero();
  bed.hi = Eigen::Vector3d(width, width, 16e-3);
  bed.cut_hi = Eigen::Vector3d(width, width, 13e-3);
  bed.skin = 0.1e-3;
  bed.steps = 300;
  bed.particles = std::make_shared<test::ThrownBed>(
      test::thrown_bed(bed.lo, Eigen::Vector3d(width, width, 8e-3), 5, 0x2545f4914f6cdd1dull));
  const test::SaggingPlate plate{width, 8, 8.3e-3, 0.8, 0.3e-3};
  bed.system = [lo = bed.lo, hi = bed.hi, plate, b = bed.particles](const std::vector<int>& keep) {
    auto sys = std::make_unique<System>();
    const int m = sys->add_material({1.0e7, 0.3, 2500.0});
    sys->add_interaction(m, m, {0.5, 0.5, 0.05});
    sys->set_gravity({0, 0, -9.81});
    test::add_bed_particles(*sys, *b, keep, m);
    sys->add_box(lo, hi, m, 0b111101);
    sys->add_plane({hi.x(), 0, 0}, {-1, 0, 0}, m, {-0.5, 0, 0});
    sys->add_mesh(plate.vertices(0.0, 1.0), plate.triangles(), m);
    return sys;
  };
  bed.before_step = [plate, steps = bed.steps](System& sys, long s, double dt) {
    sys.set_vertex_positions(0, plate.vertices((s + 1) * dt, steps * dt));
  };
  return bed;
}

// ---- a run -----------------------------------------------------------------------------------

struct Motion {
  double x[3], v[3], w[3];
};

// What one subdomain (rank) ends with: its owned particles, the collective sums, counts.
struct Result {
  std::map<std::int64_t, Motion> owned;
  std::vector<double> sums;
  std::int64_t builds = 0, migrated = 0, ghosts = 0;
  double time = 0.0;  // [s] at the end
};

void put(std::vector<std::byte>& out, const void* v, std::size_t n) {
  const std::size_t at = out.size();
  out.resize(at + n);
  std::memcpy(out.data() + at, v, n);
}
template <class T>
void put(std::vector<std::byte>& out, const T& v) {
  put(out, &v, sizeof v);
}
template <class T>
T take(const std::byte*& at) {
  T v;
  std::memcpy(&v, at, sizeof v);
  at += sizeof v;
  return v;
}

std::vector<std::byte> pack(const Result& r) {
  std::vector<std::byte> out;
  put(out, static_cast<std::uint64_t>(r.owned.size()));
  for (const auto& [id, m] : r.owned) {
    put(out, id);
    put(out, m);
  }
  put(out, static_cast<std::uint64_t>(r.sums.size()));
  put(out, r.sums.data(), 8 * r.sums.size());
  put(out, r.builds), put(out, r.migrated), put(out, r.ghosts);
  return out;
}

Result unpack(const std::vector<std::byte>& in) {
  Result r;
  const std::byte* at = in.data();
  const auto n = take<std::uint64_t>(at);
  for (std::uint64_t k = 0; k < n; ++k) {
    const auto id = take<std::int64_t>(at);
    r.owned[id] = take<Motion>(at);
  }
  r.sums.resize(take<std::uint64_t>(at));
  std::memcpy(r.sums.data(), at, 8 * r.sums.size());
  at += 8 * r.sums.size();
  r.builds = take<std::int64_t>(at), r.migrated = take<std::int64_t>(at),
  r.ghosts = take<std::int64_t>(at);
  if (at != in.data() + in.size()) throw Error("a rank's result has bytes after its end");
  return r;
}

struct Stall {
  int rank = -1;
  long step = -1;
  double seconds = 0.0;
};

// How the split is stepped besides the bed.
struct Knobs {
  Stall stall;
  SubdomainStepper::Options options;  // ghost_distance 0: no ghosts (the bits must differ)
};

std::vector<Eigen::Vector3d> start_positions(const Bed& bed) {
  std::vector<Eigen::Vector3d> x0;
  for (Eigen::Index i = 0; i < bed.particles->x.rows(); ++i)
    x0.push_back(bed.particles->x.row(i).transpose());
  return x0;
}

// The time step: a quarter of the Rayleigh time of the whole bed (alike on every rank).
double time_step(const Bed& bed) {
  std::vector<int> all(static_cast<std::size_t>(bed.particles->x.rows()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return 0.25 * bed.system(all)->rayleigh_time_step();
}

// A bisection of the bed's starting positions into `parts` boxes.
DomainDecomposition cut(const Bed& bed, int parts) {
  return DomainDecomposition::bisection(start_positions(bed), bed.lo, bed.cut_hi, parts);
}

// Steps [from, to) of the bed (the meshes moved before each).
void step_range(const Bed& bed, SubdomainStepper& stepper, System& sys, long from, long to,
                double dt, const Knobs& knobs) {
  const int rank = stepper.subdomain(0).rank();
  for (long s = from; s < to; ++s) {
    if (s == knobs.stall.step && rank == knobs.stall.rank) {
      std::fprintf(stderr, "rank %d: sleeping %g s before step %ld\n", rank, knobs.stall.seconds, s);
      std::this_thread::sleep_for(std::chrono::duration<double>(knobs.stall.seconds));
    }
    if (bed.before_step) bed.before_step(sys, s, dt);
    stepper.step(dt);
  }
}

// This subdomain's owned particles and the collective sums at the end.
Result result(const Bed& bed, SubdomainStepper& stepper, System& sys, double dt) {
  Result r;
  const Subdomain& sd = stepper.subdomain(0);
  const Particles& p = sys.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (sd.is_ghost(i)) continue;
    Motion m;
    for (int c = 0; c < 3; ++c)
      m.x[c] = p.position[i][c], m.v[c] = p.velocity[i][c], m.w[c] = p.angular_velocity[i][c];
    r.owned[p.id[i]] = m;
  }
  const auto add = [&](const auto& v) {
    for (Eigen::Index k = 0; k < v.size(); ++k) r.sums.push_back(v(k));
  };
  r.sums.push_back(stepper.kinetic_energy());
  add(stepper.linear_momentum());
  r.sums.push_back(stepper.elastic_energy());
  r.sums.push_back(static_cast<double>(stepper.contact_count()));
  for (int w = 0; w < sys.wall_count(); ++w) add(stepper.wall_force(w));
  for (const Eigen::Vector3d& f : stepper.wall_forces()) add(f);
  for (const Eigen::Vector3d& f : stepper.plane_forces()) add(f);
  for (int m = 0; m < sys.mesh_count(); ++m) {
    add(stepper.mesh_force(m));
    add(Eigen::VectorXd(stepper.triangle_forces(m).reshaped()));
    add(Eigen::VectorXd(stepper.vertex_forces(m).reshaped()));
  }
  const System::Energies e = stepper.energies();  // the energy books
  for (const double v : {e.damping, e.friction, e.gravity, e.stiffening, e.kinetic_start,
                         e.elastic_start})
    r.sums.push_back(v);
  r.sums.insert(r.sums.end(), e.wall_work.begin(), e.wall_work.end());
  r.sums.insert(r.sums.end(), e.mesh_work.begin(), e.mesh_work.end());
  r.sums.push_back(stepper.energy_balance_error());
  r.builds = stepper.builds();
  r.time = static_cast<double>(bed.steps) * dt;
  r.migrated = sd.migrated_in();
  r.ghosts = static_cast<std::int64_t>(sd.ghost_count());
  return r;
}

// The bed split by a bisection into transport.parts() boxes, this process's subdomain stepped
// over `transport` (one local subdomain) from the start to the end.
Result run(const Bed& bed, SubdomainTransport& transport, const Knobs& knobs) {
  const DomainDecomposition d = cut(bed, transport.parts());
  std::vector<int> keep;
  const std::vector<Eigen::Vector3d> x0 = start_positions(bed);
  for (std::size_t i = 0; i < x0.size(); ++i)
    if (d.owner(x0[i]) == transport.local()[0]) keep.push_back(static_cast<int>(i));
  const double dt = time_step(bed);
  std::unique_ptr<System> sys = bed.system(keep);
  SubdomainStepper stepper({sys.get()}, transport, d, bed.skin, knobs.options);
  stepper.set_energy_accounting(true);
  step_range(bed, stepper, *sys, 0, bed.steps, dt, knobs);
  return result(bed, stepper, *sys, dt);
}

// The same to step `at` over `writers`; the SplitRestart stream it gathers (on the process of
// subdomain 0; empty on the others).
std::string write_restart(const Bed& bed, SubdomainTransport& writers, long at) {
  const DomainDecomposition d = cut(bed, writers.parts());
  std::vector<int> keep;
  const std::vector<Eigen::Vector3d> x0 = start_positions(bed);
  for (std::size_t i = 0; i < x0.size(); ++i)
    if (d.owner(x0[i]) == writers.local()[0]) keep.push_back(static_cast<int>(i));
  std::unique_ptr<System> sys = bed.system(keep);
  SubdomainStepper stepper({sys.get()}, writers, d, bed.skin);
  stepper.set_energy_accounting(true);
  step_range(bed, stepper, *sys, 0, at, time_step(bed), {});
  const SplitRestart restart = SplitRestart::gather(stepper);
  if (!restart.holds()) return {};
  std::ostringstream out(std::ios::binary);
  restart.write(out);
  return std::move(out).str();
}

// A restart stream (read by every process) resumed over `readers` from step `at` to the end.
Result resume(const Bed& bed, SubdomainTransport& readers, const std::string& stream, long at) {
  std::istringstream in(stream, std::ios::binary);
  const SplitRestart restart = SplitRestart::read(in);
  std::unique_ptr<System> sys = bed.system({});
  restart.restore({sys.get()}, readers);
  SubdomainStepper stepper({sys.get()}, readers, cut(bed, readers.parts()), bed.skin);
  stepper.set_energy_accounting(true);
  stepper.resume();
  stepper.restore_books(restart.books());
  const double dt = time_step(bed);
  step_range(bed, stepper, *sys, at, bed.steps, dt, {});
  return result(bed, stepper, *sys, dt);
}

bool same_bits(const double* a, const double* b, int n) { return std::memcmp(a, b, 8 * n) == 0; }

// Rank 0: every rank's result against `ref`, the bed stepped in one subdomain; prints what
// differs. name: what ran.
bool compare(const std::string& name, const Bed& bed, const std::vector<Result>& ranks,
             const Result& ref) {
  const auto n = static_cast<std::size_t>(bed.particles->x.rows());
  bool ok = true;
  const auto fail = [&](const std::string& what) {
    std::fprintf(stderr, "FAILED: %s: %s\n", name.c_str(), what.c_str());
    ok = false;
  };
  if (ref.owned.size() != n) fail("the reference holds " + std::to_string(ref.owned.size()) + " particles");
  if (ref.builds < 4) fail("the reference built its lists " + std::to_string(ref.builds) + " times");
  std::map<std::int64_t, Motion> all;
  std::int64_t migrated = 0, ghosts = 0;
  for (std::size_t k = 0; k < ranks.size(); ++k) {
    const Result& r = ranks[k];
    for (const auto& [id, m] : r.owned)
      if (!all.emplace(id, m).second) fail("particle " + std::to_string(id) + " owned twice");
    migrated += r.migrated, ghosts += r.ghosts;
    if (r.builds != ref.builds)
      fail("rank " + std::to_string(k) + " built its lists " + std::to_string(r.builds) +
           " times, one subdomain " + std::to_string(ref.builds));
    if (r.sums.size() != ref.sums.size() ||
        !same_bits(r.sums.data(), ref.sums.data(), static_cast<int>(ref.sums.size()))) {
      std::size_t q = 0;
      while (q < std::min(r.sums.size(), ref.sums.size()) && r.sums[q] == ref.sums[q]) ++q;
      char text[200];
      std::snprintf(text, sizeof text, "rank %zu's collective sum %zu is %a, one subdomain's %a",
                    k, q, q < r.sums.size() ? r.sums[q] : 0.0,
                    q < ref.sums.size() ? ref.sums[q] : 0.0);
      fail(text);
    }
  }
  if (all.size() != n) fail(std::to_string(all.size()) + " particles over the ranks, not " + std::to_string(n));
  std::size_t differ = 0;
  for (const auto& [id, m] : ref.owned) {
    const auto it = all.find(id);
    if (it != all.end() && same_bits(it->second.x, m.x, 9)) continue;
    if (++differ == 1 && it != all.end()) {
      char text[300];
      std::snprintf(text, sizeof text, "particle %lld: x (%a, %a, %a), one subdomain (%a, %a, %a)",
                    static_cast<long long>(id), it->second.x[0], it->second.x[1], it->second.x[2],
                    m.x[0], m.x[1], m.x[2]);
      fail(text);
    }
  }
  if (differ > 0) fail(std::to_string(differ) + " of " + std::to_string(n) + " particles differ in x, v or omega");
  if (ranks.size() > 1) {
    if (migrated < bed.min_migrated)
      fail(std::to_string(migrated) + " particles changed rank; the bed is meant to make at least " +
           std::to_string(bed.min_migrated));
    if (ghosts == 0) fail("no ghosts at the end");
  }
  std::printf("%s: %zu particles, %g ms, %lld list builds, %lld particles changed rank, "
              "%lld ghosts at the end, %zu collective sums: %s\n",
              name.c_str(), n, 1e3 * ref.time, static_cast<long long>(ref.builds),
              static_cast<long long>(migrated), static_cast<long long>(ghosts), ref.sums.size(),
              ok ? "the bits of one subdomain" : "DIFFERENT");
  return ok;
}

int usage(const char* why) {
  std::fprintf(stderr,
               "%s\nusage: mpirun -n N partita_dem_mpi_subdomains gravity|pressed|crossing "
               "[--deadline S] [--piece BYTES] [--stall RANK STEP SECONDS] [--no-ghosts]\n"
               "       [--restart WRITERS READERS STEP FILE] (on max(WRITERS, READERS) ranks)\n",
               why);
  return 2;
}

// Every rank's result to rank 0, through the transport (its deadline included); on the others
// none.
std::vector<Result> gather_results(MpiSubdomainTransport& transport, const Result& mine) {
  std::vector<SubdomainMail> out(1, SubdomainMail(static_cast<std::size_t>(transport.parts())));
  std::vector<SubdomainMail> in;
  out[0][0] = pack(mine);
  transport.exchange(out, in);
  std::vector<Result> ranks;
  if (transport.rank() == 0)
    for (const std::vector<std::byte>& m : in[0]) ranks.push_back(unpack(m));
  return ranks;
}

// The bed stepped to step `at` on the first `writers` ranks, its SplitRestart gathered to rank 0
// and written to `file`, read by the first `readers` ranks and resumed to the end, against the
// same in one subdomain written and resumed in one process.
int restarted(const std::string& name, const Bed& bed, double deadline, int writers, int readers,
              long at, const std::string& file, int rank) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (writers < 1 || readers < 1 || size != std::max(writers, readers) || at >= bed.steps)
    return usage(("--restart: run on max(WRITERS, READERS) ranks, a step before the " +
                  std::to_string(bed.steps) + "th")
                     .c_str());
  MpiSubdomainTransport world(MPI_COMM_WORLD, deadline);
  MPI_Comm write_comm, read_comm;
  MPI_Comm_split(MPI_COMM_WORLD, rank < writers ? 0 : MPI_UNDEFINED, rank, &write_comm);
  MPI_Comm_split(MPI_COMM_WORLD, rank < readers ? 0 : MPI_UNDEFINED, rank, &read_comm);
  if (write_comm != MPI_COMM_NULL) {
    MpiSubdomainTransport transport(write_comm, deadline);
    const std::string stream = write_restart(bed, transport, at);
    if (rank == 0) {
      std::ofstream out(file, std::ios::binary);
      out.write(stream.data(), static_cast<std::streamsize>(stream.size()));
      if (!out.flush()) throw Error("cannot write " + file);
    }
  }
  world.max({0.0});  // (the stream is written)
  std::vector<Result> ranks;
  if (read_comm != MPI_COMM_NULL) {
    std::ifstream in(file, std::ios::binary);
    const std::string stream((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    MpiSubdomainTransport transport(read_comm, deadline);
    ranks = gather_results(transport, resume(bed, transport, stream, at));
  }
  for (MPI_Comm* c : {&write_comm, &read_comm})
    if (*c != MPI_COMM_NULL) MPI_Comm_free(c);
  if (rank != 0) return 0;
  std::remove(file.c_str());  // (every reader has read it: their results are here)
  InProcessTransport one(1), other(1);
  const Result ref = resume(bed, other, write_restart(bed, one, at), at);
  return compare(name + " bed written on " + std::to_string(writers) + " ranks at step " +
                     std::to_string(at) + ", resumed on " + std::to_string(readers),
                 bed, ranks, ref)
             ? 0
             : 1;
}

int main_mpi(int argc, char** argv, int rank) {
  if (argc < 2) return usage("no bed named");
  const std::string name = argv[1];
  Bed bed = name == "gravity" ? gravity_bed() : name == "pressed" ? pressed_bed()
          : name == "crossing" ? crossing_bed() : Bed{};
  if (!bed.system) return usage(("no bed '" + name + "'").c_str());
  // the crossing bed travels about 6 mm (3 m/s for about 2 ms), as far as the median cut is from
  // the start: at least a quarter of its particles change rank
  if (name == "crossing") bed.min_migrated = bed.particles->x.rows() / 4;
  double deadline = 30.0;
  long piece = 0;
  Knobs knobs;
  Stall& stall = knobs.stall;
  int writers = 0, readers = 0;
  long restart_at = 0;
  std::string file;
  for (int k = 2; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--deadline" && k + 1 < argc)
      deadline = std::stod(argv[++k]);
    else if (a == "--restart" && k + 4 < argc)
      writers = std::stoi(argv[k + 1]), readers = std::stoi(argv[k + 2]),
      restart_at = std::stol(argv[k + 3]), file = argv[k + 4], k += 4;
    else if (a == "--no-ghosts")
      knobs.options.ghost_distance = 0.0;
    else if (a == "--piece" && k + 1 < argc)
      piece = std::stol(argv[++k]);
    else if (a == "--stall" && k + 3 < argc)
      stall.rank = std::stoi(argv[k + 1]), stall.step = std::stol(argv[k + 2]),
      stall.seconds = std::stod(argv[k + 3]), k += 3;
    else
      return usage(("unknown argument '" + a + "'").c_str());
  }
  if (restart_at > 0) return restarted(name, bed, deadline, writers, readers, restart_at, file, rank);
  MpiSubdomainTransport transport(MPI_COMM_WORLD, deadline);
  if (piece > 0) transport.set_piece_bytes(static_cast<std::uint64_t>(piece));
  const std::vector<Result> ranks = gather_results(transport, run(bed, transport, knobs));
  if (rank != 0) return 0;
  InProcessTransport one(1);
  return compare(name + " bed on " + std::to_string(ranks.size()) + " ranks", bed, ranks,
                 run(bed, one, {}))
             ? 0
             : 1;
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int status = 0;
  try {
    status = main_mpi(argc, argv, rank);
  } catch (const PeerTimeout& e) {
    std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 3);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  MPI_Finalize();
  return status;
}
