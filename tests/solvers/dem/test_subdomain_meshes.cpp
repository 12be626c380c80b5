// A split bed with a triangle-mesh wall (SubdomainStepper): a polydisperse bed with friction in
// a box, pressed by a plate mesh moved and deformed through set_vertex_positions() every step (as
// the coupling moves an FE surface) and squeezed by a moving side plane, steps to the same bits
// on 1, 2, 3 and 4 subdomains, and the mesh's force per triangle and in total, summed over the
// subdomains' owned particles, is the same on any split; a ghost has no mesh contacts, so each
// System's own mesh forces added up are the bed's (rounded in another order), and without the
// mesh histories in the build messages the split differs. A split whose subdomain is empty at first (its walls
// and mesh must move all the same) keeps the bits once particles reach it. A restart written on
// P subdomains resumes on M with the bits of 1 on 1. The split's energy books (the owned
// particles' terms of every step in exact sums) close, match one System's books of the bed
// stepped whole, are the same bits on any split and go on through a restart.

#include "subdomain_test_helpers.hpp"

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/subdomain.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>
#include <utility>

using namespace partita::dem;

namespace {

constexpr double kWidth = 12e-3, kBedHeight = 8e-3, kBoxHeight = 16e-3;
constexpr double kSkin = 0.1e-3;
constexpr double kPlateStart = kBedHeight + 0.3e-3;  // the plate's height at first
constexpr double kPlateSpeed = 0.8;                  // down [m/s]
constexpr double kBulge = 0.3e-3;                    // the plate's sag at the end [m]
constexpr double kSideSpeed = 0.5;                   // the +x plane, inwards [m/s]
constexpr int kCells = 8;  // the plate: kCells^2 squares, 2 triangles each
constexpr long kSteps = 300;
const Eigen::Vector3d kLo = Eigen::Vector3d::Zero();
const Eigen::Vector3d kHi(kWidth, kWidth, kBoxHeight);
// the decomposition's bounds: the bed and the plate's way, tallest upright (a bisection cuts
// across z first, then upright: on 3 and 4 subdomains the plate spans several)
const Eigen::Vector3d kCutHi(kWidth, kWidth, 13e-3);

using Bed = test::ThrownBed;

const Bed& bed() {
  static const Bed b =
      test::thrown_bed(kLo, Eigen::Vector3d(kWidth, kWidth, kBedHeight), 5, 0x2545f4914f6cdd1dull);
  return b;
}

// The plate: a (kCells + 1)^2 grid over the box's width, going down at kPlateSpeed and sagging in
// the middle by up to kBulge at the end of the run (time t_end).
const test::SaggingPlate kPlate{kWidth, kCells, kPlateStart, kPlateSpeed, kBulge};
Eigen::MatrixX3d plate(double t, double t_end) { return kPlate.vertices(t, t_end); }
TriangleMesh::Triangles plate_triangles() { return kPlate.triangles(); }

// One subdomain's System, alike on every subdomain: the box without its +x face (wall 0), the
// +x plane moving inwards (wall 1), the plate (mesh 0), the particles of `keep` (id = index).
std::unique_ptr<System> subdomain_system(const std::vector<int>& keep) {
  auto sys = test::bed_system(bed(), keep);
  const int m = 0;  // (its material)
  sys->add_box(kLo, kHi, m, 0b111101);
  sys->add_plane({kWidth, 0, 0}, {-1, 0, 0}, m, {-kSideSpeed, 0, 0});
  sys->add_mesh(plate(0.0, 1.0), plate_triangles(), m);
  return sys;
}

double time_step() {
  static const double dt = 0.25 * subdomain_system({0, 1, 2})->rayleigh_time_step();
  return dt;
}

// One System::pack_particles() message (header 41 bytes: n at 16, pair records at 24, the mesh
// bytes at 32; the particles, the records of PairContacts::record_bytes, then per particle a count (int32) and its
// contacts) with every particle's count 0: a particle arrives without its tangential springs on
// the plate. Adds the contacts taken out to `stripped`.
std::vector<std::byte> without_mesh_contacts(System& any, const std::byte* m, std::size_t bytes,
                                             long& stripped) {
  using test::read_at;
  const auto n = read_at<std::uint64_t>(m + 16), records = read_at<std::uint64_t>(m + 24);
  const std::size_t mesh_at =
      41 + n * any.store_unsynced().packed_bytes_per_particle() + records * PairContacts::record_bytes;
  stripped += static_cast<long>((bytes - mesh_at - 4 * n) / MeshContacts::packed_contact_bytes);
  std::vector<std::byte> out(m, m + mesh_at);
  out.resize(mesh_at + 4 * n, std::byte{0});
  const std::uint64_t mesh_bytes = 4 * n;
  std::memcpy(out.data() + 32, &mesh_bytes, 8);
  return out;
}

struct Run {
  test::MotionById state;  // owned particles by id
  long builds = 0, migrated = 0;
  std::size_t ghosts_at_end = 0;
  bool empty_at_first = false;  // some subdomain held no particle after the first step
  bool all_owning_at_end = true;
  Eigen::MatrixX3d triangle, vertex;  // SubdomainStepper's, at the end
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  Eigen::MatrixX3d system_triangle;  // System::triangle_forces(0) summed over the subdomains
  Eigen::Vector3d system_total = Eigen::Vector3d::Zero();  // System::mesh_force(0) summed
  Eigen::Vector3d wall = Eigen::Vector3d::Zero();          // SubdomainStepper::wall_force(1)
  std::size_t contacts = 0;  // the owned particles' mesh contacts at the end
  long stripped = 0;         // mesh contacts taken out of the messages (without_mesh_histories)
  System::Energies energies;  // (Plan::energy) SubdomainStepper's books at the end
  double balance = 0.0;       // (the same) its energy_balance_error()
  double kinetic = 0.0, elastic = 0.0;
};

std::vector<Eigen::Vector3d> start_positions() { return test::positions(bed()); }

// What a run does besides stepping: a re-cut (a bisection of the positions of step recut_at
// from then on), the mesh contacts taken out of the build messages, a restart at step
// restart_at on restart_parts subdomains.
struct Plan {
  long recut_at = 0;
  bool without_mesh_histories = false;
  long restart_at = 0;
  int restart_parts = 1;
  bool energy = false;  // the split's energy accounting
  int finer = 1;        // the same run in `finer` times as many steps
};

// A restart of `old` on `parts` subdomains: written to a stream (SplitRestart), read back into
// new Systems set up alike.
std::vector<std::unique_ptr<System>> restart_systems(SubdomainStepper& old, int parts,
                                                     std::vector<std::byte>& books) {
  std::stringstream file;
  SplitRestart::gather(old).write(file);
  const SplitRestart restart = SplitRestart::read(file);
  books = restart.books();
  test::SplitSystems s = test::make_systems(parts, [](int) { return subdomain_system({}); });
  restart.restore(s.raw);
  return std::move(s.systems);
}

// The bed split by `d` (parts = its boxes), kSteps steps.
Run run_split(const DomainDecomposition& d, const Plan& plan = {}) {
  int parts = d.parts();
  const std::vector<std::vector<int>> keep = test::owned_at(d, start_positions());
  auto [systems, raw] = test::make_systems(parts, [&](int k) { return subdomain_system(keep[k]); });
  auto in_process = std::make_unique<InProcessTransport>(parts);
  long stripped = 0;
  test::RewritingTransport stripping(*in_process, [&](const std::byte* m, std::size_t bytes) {
    return without_mesh_contacts(*systems[0], m, bytes, stripped);
  });
  SubdomainTransport* transport =
      plan.without_mesh_histories ? static_cast<SubdomainTransport*>(&stripping) : in_process.get();
  auto stepper = std::make_unique<SubdomainStepper>(raw, *transport, d, kSkin);
  stepper->set_energy_accounting(plan.energy);
  const long steps = kSteps * plan.finer;
  const double dt = time_step() / static_cast<double>(plan.finer), t_end = steps * dt;
  Run out;
  for (long s = 0; s < steps; ++s) {
    if (plan.recut_at > 0 && s == plan.recut_at)
      stepper->set_decomposition(
          DomainDecomposition::bisection(test::owned_positions(*stepper), kLo, kCutHi, parts));
    if (plan.restart_at > 0 && s == plan.restart_at) {
      std::vector<std::byte> books;
      std::vector<std::unique_ptr<System>> next =
          restart_systems(*stepper, plan.restart_parts, books);
      parts = plan.restart_parts;
      const Particles& p = next[0]->particles();
      const std::vector<Eigen::Vector3d> x(p.position.begin(), p.position.end());
      raw.clear();
      for (auto& sys : next) raw.push_back(sys.get());
      auto next_transport = std::make_unique<InProcessTransport>(parts);
      auto next_stepper = std::make_unique<SubdomainStepper>(
          raw, *next_transport, DomainDecomposition::bisection(x, kLo, kCutHi, parts), kSkin);
      stepper = std::move(next_stepper);  // (the old stepper before its systems)
      systems = std::move(next);
      in_process = std::move(next_transport);
      stepper->set_energy_accounting(plan.energy);
      stepper->resume();
      if (plan.energy) stepper->restore_books(books);
    }
    const Eigen::MatrixX3d xp = plate((s + 1) * dt, t_end);  // the plate at the step's end
    for (System* sys : raw) sys->set_vertex_positions(0, xp);
    stepper->step(dt);
    if (s == 0)
      for (System* sys : raw) out.empty_at_first = out.empty_at_first || sys->particle_count() == 0;
  }
  for (int k = 0; k < parts; ++k) {
    const Subdomain& sd = stepper->subdomain(k);
    const Particles& p = systems[k]->particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!sd.is_ghost(i))
        out.state[p.id[i]] = {p.position[i], p.velocity[i], p.angular_velocity[i]};
    sd.system().mesh_contacts().for_each_contact(
        [&](int i, const MeshContactRecord&, const Eigen::Vector3d&) {
          out.contacts += sd.is_ghost(static_cast<std::size_t>(i)) ? 0 : 1;
        });
    out.migrated += sd.migrated_in();
    out.ghosts_at_end += sd.ghost_count();
    out.all_owning_at_end = out.all_owning_at_end && sd.owned_count() > 0;
  }
  out.triangle = stepper->triangle_forces(0);
  out.vertex = stepper->vertex_forces(0);
  out.total = stepper->mesh_force(0);
  out.wall = stepper->wall_force(1);
  out.system_triangle.setZero(out.triangle.rows(), 3);
  for (int k = 0; k < parts; ++k) {
    out.system_triangle += systems[k]->triangle_forces(0);
    out.system_total += systems[k]->mesh_force(0);
  }
  out.builds = stepper->builds();
  out.stripped = stripped;
  if (plan.energy) {
    out.energies = stepper->energies();
    out.balance = stepper->energy_balance_error();
    out.kinetic = stepper->kinetic_energy();
    out.elastic = stepper->elastic_energy();
  }
  return out;
}

Run run_bisection(int parts) {
  return run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, parts));
}

std::size_t differing(const Run& a, const Run& ref) {
  return test::differing(a.state, ref.state);
}

// The sum of |force| over the triangles (the scale of a rounding difference).
double scale(const Eigen::MatrixX3d& f) {
  return f.rowwise().norm().sum();
}

const Run& reference() {
  static const Run r = run_bisection(1);
  return r;
}

}  // namespace

TEST_CASE(
    "dem: subdomains: a bed pressed by a moving mesh plate steps to the same bits and "
    "mesh forces on 1 to 4 subdomains",
    "[dem][subdomains]") {
  const Run& ref = reference();
  REQUIRE(ref.state.size() == static_cast<std::size_t>(bed().x.rows()));
  REQUIRE(ref.state.size() > 1000);
  REQUIRE(ref.builds >= 10);
  // the plate presses the bed: many contacts, most triangles loaded, the bed pushes it up
  REQUIRE(ref.contacts > 50);
  int loaded = 0;
  for (Eigen::Index t = 0; t < ref.triangle.rows(); ++t) loaded += ref.triangle.row(t).norm() > 0.0;
  CHECK(loaded > ref.triangle.rows() / 2);
  CHECK(ref.total.z() > 0.0);
  CHECK(ref.wall.x() > 0.0);  // the moving side plane is pushed outwards (+x)
  // contracts: the triangles' and the vertices' forces add up to the total (rounding apart), and
  // one subdomain's exact sums agree with the System's own sums (rounding apart)
  const double s = scale(ref.triangle);
  CHECK((ref.triangle.colwise().sum().transpose() - ref.total).norm() <= 1e-12 * s);
  CHECK((ref.vertex.colwise().sum().transpose() - ref.total).norm() <= 1e-12 * s);
  CHECK((ref.triangle - ref.system_triangle).cwiseAbs().maxCoeff() <= 1e-12 * s);
  CHECK((ref.total - ref.system_total).norm() <= 1e-12 * s);
  for (const int parts : {2, 3, 4}) {
    CAPTURE(parts);
    const Run split = run_bisection(parts);
    CHECK(split.builds == ref.builds);
    CHECK(split.migrated > 0);
    CHECK(split.ghosts_at_end > 0);
    CHECK(differing(split, ref) == 0);
    CHECK(split.contacts == ref.contacts);
    CHECK(split.triangle == ref.triangle);
    CHECK(split.vertex == ref.vertex);
    CHECK(split.total == ref.total);
    CHECK(split.wall == ref.wall);
    // a ghost has no contacts with the plate (its own force is not used: it is listed for its
    // pairs with the owned particles only), so each System's own sums, added over the
    // subdomains, are the bed's forces, rounded in another order
    CHECK((split.system_triangle - ref.triangle).cwiseAbs().maxCoeff() <= 1e-12 * s);
    CHECK((split.system_total - ref.total).norm() <= 1e-12 * s);
  }
}

TEST_CASE(
    "dem: subdomains: a subdomain empty at first moves its walls and mesh and keeps the "
    "bits when particles reach it",
    "[dem][subdomains]") {
  // cuts made for the bed and twice as many points again near the top of the bounds: two boxes
  // above the bed hold nothing (no ghost either); then a bisection of the particles gives every
  // subdomain some
  std::vector<Eigen::Vector3d> x = start_positions();
  const std::size_t n = x.size();
  for (std::size_t k = 0; k < 2 * n; ++k)
    x.emplace_back(kWidth * (k % 97) / 97.0, kWidth * (k % 89) / 89.0, kCutHi.z() - 0.5e-3);
  const DomainDecomposition d = DomainDecomposition::bisection(x, kLo, kCutHi, 3);
  Plan plan;
  plan.recut_at = kSteps / 3;
  const Run split = run_split(d, plan);
  CHECK(split.empty_at_first);
  CHECK(split.all_owning_at_end);
  CHECK(differing(split, reference()) == 0);
  CHECK(split.triangle == reference().triangle);
  CHECK(split.wall == reference().wall);
}

TEST_CASE("dem: subdomains: the mesh forces of a split bed do not depend on the thread count",
          "[dem][subdomains]") {
  const int threads = max_threads();
  set_num_threads(threads == 1 ? 2 : 1);
  const Run split = run_bisection(3);
  set_num_threads(threads);
  CHECK(differing(split, reference()) == 0);
  CHECK(split.triangle == reference().triangle);
  CHECK(split.total == reference().total);
}

TEST_CASE("dem: subdomains: without the mesh histories in the messages the split differs",
          "[dem][subdomains]") {
  Plan plan;
  plan.without_mesh_histories = true;
  const Run split =
      run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, 3), plan);
  CHECK(split.stripped > 0);
  CHECK(differing(split, reference()) > 0);
}

TEST_CASE("dem: subdomains: a restart written on P subdomains resumes on M with the same bits",
          "[dem][subdomains]") {
  const auto restarted = [](int written, int resumed) {
    Plan plan;
    plan.restart_at = kSteps / 2;
    plan.restart_parts = resumed;
    return run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, written), plan);
  };
  const Run one = restarted(1, 1);
  REQUIRE(one.state.size() == reference().state.size());
  CHECK(one.builds >= 5);  // (after the restart)
  // the restart carries everything: the run goes on as it would have, up to rounding (a list
  // build at the restart may renumber particles: their contacts summed in another order)
  double off = 0.0;
  for (const auto& [id, s] : reference().state)
    off = std::max(off, (one.state.at(id).x - s.x).norm());
  CHECK(off < 1e-6);
  for (const auto& [written, resumed] : std::vector<std::pair<int, int>>{{2, 3}, {3, 1}, {4, 2}}) {
    CAPTURE(written, resumed);
    const Run split = restarted(written, resumed);
    CHECK(differing(split, one) == 0);
    CHECK(split.triangle == one.triangle);
    CHECK(split.wall == one.wall);
  }
}

namespace {

// The books as a list: damping, friction, gravity, stiffening, each wall's and mesh's work, the
// start values.
std::vector<double> book_values(const System::Energies& e) {
  std::vector<double> v{e.damping, e.friction, e.gravity, e.stiffening, e.kinetic_start,
                        e.elastic_start, e.breakage};
  v.insert(v.end(), e.wall_work.begin(), e.wall_work.end());
  v.insert(v.end(), e.mesh_work.begin(), e.mesh_work.end());
  return v;
}

// The bed of run_split() in one System stepped whole (System::step(), its own energy
// accounting), with the plan's step
// The run with the split's energy accounting in four times as many steps, on one subdomain: at a
// quarter of the Rayleigh step the plate and the side plane squeeze this soft bed faster than its
// tangential springs are resolved (one System's books of it miss by 90 %, 2 % at an eighth, 0.07 %
// at a sixteenth)
Plan energy_plan() {
  Plan plan;
  plan.energy = true;
  plan.finer = 4;
  return plan;
}
const Run& energy_reference() {
  static const Run r =
      run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, 1), energy_plan());
  return r;
}

// The largest difference between two runs' books over the sum of their magnitudes.
double books_apart(const System::Energies& a, const System::Energies& b) {
  const std::vector<double> x = book_values(a), y = book_values(b);
  REQUIRE(x.size() == y.size());
  double scale = 0.0, off = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    scale += std::abs(y[k]);
    off = std::max(off, std::abs(x[k] - y[k]));
  }
  return off / scale;
}

System::Energies whole_bed_energies(const Plan& plan, double& balance) {
  std::vector<int> all(static_cast<std::size_t>(bed().x.rows()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  auto sys = subdomain_system(all);
  sys->set_skin(kSkin);
  sys->set_energy_tracking(true);
  const long steps = kSteps * plan.finer;
  const double dt = time_step() / static_cast<double>(plan.finer), t_end = steps * dt;
  for (long s = 0; s < steps; ++s) {
    sys->set_vertex_positions(0, plate((s + 1) * dt, t_end));
    sys->step(dt);
  }
  balance = sys->energy_balance_error();
  return sys->energies();
}

}  // namespace

TEST_CASE(
    "dem: subdomains: the energy books of a split bed close and are the same bits on 1 to 4 "
    "subdomains",
    "[dem][subdomains][energy]") {
  const Plan plan = energy_plan();
  const Run& one = energy_reference();
  const System::Energies& e = one.energies;
  REQUIRE(e.started);
  REQUIRE(e.wall_work.size() == 2);
  REQUIRE(e.mesh_work.size() == 1);
  // what the run does: the plate and the side plane push into the bed (work in), friction and
  // damping dissipate, the contacts store
  CHECK(e.mesh_work[0] > 0.0);
  CHECK(e.wall_work[1] > 0.0);
  CHECK(e.wall_work[0] == 0.0);  // (the box stands still)
  CHECK(e.friction > 0.0);
  CHECK(e.damping > 0.0);
  CHECK(one.elastic > 0.0);
  // the books close: the work in is the change of the stored energy plus the dissipation, up to
  // the trapezoidal rule's error on the contact springs
  CHECK(std::abs(one.balance) < 2e-3);
  // and they are the books one System keeps of the same bed stepped whole (its sums in another
  // order, its motion the same up to rounding)
  double whole_balance = 0.0;
  const System::Energies whole = whole_bed_energies(plan, whole_balance);
  CHECK(books_apart(e, whole) <= 1e-6);
  CHECK(std::abs(one.balance - whole_balance) <= 1e-5);
  const std::vector<double> a = book_values(e);
  for (const int parts : {2, 3, 4}) {
    CAPTURE(parts);
    const Run split =
        run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, parts), plan);
    CHECK(differing(split, one) == 0);
    CHECK(book_values(split.energies) == a);
    CHECK(split.balance == one.balance);
  }
  // the books do not touch the motion
  Plan without = plan;
  without.energy = false;
  CHECK(differing(run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, 2),
                            without),
                  one) == 0);
}

TEST_CASE("dem: subdomains: the energy books go on through a restart written on P subdomains "
          "and resumed on M",
          "[dem][subdomains][energy]") {
  // (the finer steps of the test above: books that close)
  const auto restarted = [](int written, int resumed) {
    Plan plan = energy_plan();
    plan.restart_at = 2 * kSteps;
    plan.restart_parts = resumed;
    return run_split(DomainDecomposition::bisection(start_positions(), kLo, kCutHi, written), plan);
  };
  const Run one = restarted(1, 1);
  REQUIRE(one.energies.started);
  // the books go on as they would have without the restart (up to rounding: a list build at the
  // restart may renumber the particles) and close
  CHECK(books_apart(one.energies, energy_reference().energies) <= 1e-6);
  CHECK(std::abs(one.balance) < 2e-3);
  for (const auto& [written, resumed] : std::vector<std::pair<int, int>>{{2, 3}, {4, 1}}) {
    CAPTURE(written, resumed);
    const Run split = restarted(written, resumed);
    CHECK(differing(split, one) == 0);
    CHECK(book_values(split.energies) == book_values(one.energies));
    CHECK(split.balance == one.balance);
  }
}

TEST_CASE(
    "dem: subdomains: the mesh sums refuse a mesh the split does not have, resume() a "
    "started run, a restart Systems with particles or bytes that are not one; a restart held "
    "elsewhere is not written",
    "[dem][subdomains]") {
  const std::vector<Eigen::Vector3d> x0 = start_positions();
  const DomainDecomposition d = DomainDecomposition::bisection(x0, kLo, kCutHi, 2);
  std::vector<int> a, b;
  for (std::size_t i = 0; i < x0.size(); ++i)
    (d.owner(x0[i]) == 0 ? a : b).push_back(static_cast<int>(i));
  auto sa = subdomain_system(a), sb = subdomain_system(b);
  InProcessTransport transport(2);
  SubdomainStepper stepper({sa.get(), sb.get()}, transport, d, kSkin);
  stepper.step(time_step());
  CHECK_THROWS_AS(stepper.triangle_forces(1), Error);
  CHECK_THROWS_AS(stepper.mesh_force(-1), Error);
  CHECK(stepper.mesh_force(0).allFinite());
  CHECK_THROWS_AS(stepper.resume(), Error);  // (a started stepper)
  // a restart into Systems that hold particles, or from a stream that is not one or ends early
  const SplitRestart restart = SplitRestart::gather(stepper);
  CHECK(restart.parts() == 2);
  CHECK_THROWS_AS(restart.restore({sa.get()}), Error);
  std::stringstream file;
  restart.write(file);
  const std::string bytes = file.str();
  std::istringstream cut(bytes.substr(0, bytes.size() - 1)), junk("not a restart at all");
  CHECK_THROWS_AS(SplitRestart::read(cut), Error);
  CHECK_THROWS_AS(SplitRestart::read(junk), Error);
  // none held (a split over processes gathers it on subdomain 0's process only)
  const SplitRestart none;
  CHECK_FALSE(none.holds());
  CHECK(restart.holds());
  std::stringstream empty;
  CHECK_THROWS_AS(none.write(empty), Error);
  CHECK_THROWS_AS(none.restore({sa.get()}), Error);
  // restored with a transport: the world everywhere, the particles to subdomain 0's System
  auto ra = subdomain_system({}), rb = subdomain_system({});
  restart.restore({ra.get(), rb.get()}, transport);
  CHECK(ra->particle_count() == x0.size());
  CHECK(rb->particle_count() == 0);
  CHECK_THROWS_AS(restart.restore({ra.get()}, transport), Error);  // (one System for two)
  // a message of sums cut short, or naming a vertex the mesh does not have
  MeshForceSums sums, other;
  sums.reset(4);
  sums.add_vertex(3, Eigen::Vector3d(1, 2, 3));
  std::vector<std::byte> m;
  sums.write(m);
  other.reset(3);
  CHECK_THROWS_AS(other.add_message(m, 1), Error);
  m.pop_back();
  other.reset(4);
  CHECK_THROWS_AS(other.add_message(m, 1), Error);
}
