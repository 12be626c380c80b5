// A bed split into subdomains (SubdomainStepper) steps to the same bits on any split: positions,
// velocities and angular velocities per particle id equal those of the same bed in one subdomain,
// with list rebuilds, particles crossing the cuts, tangential histories against each other and
// the walls, and a re-cut in the middle of the run; without ghosts the bits differ (the test can
// fail).

#include "dem_test_helpers.hpp"
#include "subdomain_test_helpers.hpp"

#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/exact_sum.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/subdomain.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <cstring>
#include <map>
#include <memory>

using namespace partita::dem;

namespace {

constexpr double kWidth = 8e-3, kHeight = 18e-3;
constexpr double kSkin = 0.05e-3;
const Eigen::Vector3d kLo = Eigen::Vector3d::Zero();
const Eigen::Vector3d kHi(kWidth, kWidth, kHeight);

// A polydisperse bed (three sizes) thrown about in a closed box of planes with friction under
// gravity: the particles collide, cross the cuts and settle; pairs and planes keep tangential
// springs.
using Bed = test::ThrownBed;

const Bed& bed() {
  static const Bed b = test::thrown_bed(kLo, kHi, 11, 0x9e3779b97f4a7c15ull);
  return b;
}

// One subdomain's System: the same set-up on every subdomain, the particles of `keep` (their
// index is their id).
std::unique_ptr<System> subdomain_system(const std::vector<int>& keep) {
  auto sys = test::bed_system(bed(), keep);
  const int m = 0;  // (its material)
  sys->add_box(kLo, kHi, m);
  return sys;
}

// One System::pack_particles() message without its pair records (header 41 bytes: n at 16, the
// record count at 24; records of PairContacts::record_bytes after the particles): the histories do not travel.
std::vector<std::byte> without_records(System& any, const std::byte* m, std::size_t bytes) {
  using test::read_at;
  const auto n = read_at<std::uint64_t>(m + 16), records = read_at<std::uint64_t>(m + 24);
  const std::size_t pairs_at = 41 + n * any.store_unsynced().packed_bytes_per_particle();
  std::vector<std::byte> out(m, m + pairs_at);
  out.insert(out.end(), m + pairs_at + records * PairContacts::record_bytes, m + bytes);
  const std::uint64_t none = 0;
  std::memcpy(out.data() + 24, &none, 8);
  return out;
}

struct Run {
  test::MotionById state;  // owned particles by id
  long builds = 0;
  long migrated = 0;
  std::size_t ghosts_at_end = 0;
  double kinetic = 0.0;              // SubdomainStepper::kinetic_energy() at the end
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  double system_kinetic = 0.0;  // System::kinetic_energy() summed over the subdomains
  double elastic = 0.0;         // SubdomainStepper::elastic_energy() at the end
  Eigen::Vector3d wall = Eigen::Vector3d::Zero();  // SubdomainStepper::wall_force(0)
  Eigen::Vector3d system_wall = Eigen::Vector3d::Zero();  // System::wall_force(0), summed
  double face_scale = 0.0;  // the sum of |face force| over the box's faces, summed
  double system_elastic = 0.0;  // System::elastic_energy() summed over the subdomains
  bool recut = false;  // the re-cut moved some box and the stepper took it up
  long steps = 0, fused_steps = 0;  // (the fused path: the first half inside the force pass)
};

// The bed split into `parts` subdomains, `steps` steps; `recut_at` > 0: a new bisection of the
// positions of that step from then on.
Run run_split(int parts, long steps, SubdomainStepper::Options options = {}, long recut_at = 0,
              bool without_histories = false) {
  const std::vector<Eigen::Vector3d> x0 = test::positions(bed());
  const DomainDecomposition d = DomainDecomposition::bisection(x0, kLo, kHi, parts);
  const std::vector<std::vector<int>> keep = test::owned_at(d, x0);
  auto [systems, raw] = test::make_systems(parts, [&](int k) { return subdomain_system(keep[k]); });
  InProcessTransport in_process(parts);
  test::RewritingTransport stripped(in_process, [&](const std::byte* m, std::size_t bytes) {
    return without_records(*systems[0], m, bytes);
  });
  SubdomainTransport& transport =
      without_histories ? static_cast<SubdomainTransport&>(stripped) : in_process;
  SubdomainStepper stepper(raw, transport, d, kSkin, options);
  const double dt = 0.25 * systems[0]->rayleigh_time_step();
  Run out;
  for (long s = 0; s < steps; ++s) {
    if (recut_at > 0 && s == recut_at) {
      const DomainDecomposition recut =
          DomainDecomposition::bisection(test::owned_positions(stepper), kLo, kHi, parts);
      for (int k = 0; k < parts; ++k)
        out.recut = out.recut || recut.box(k).lo != d.box(k).lo || recut.box(k).hi != d.box(k).hi;
      stepper.set_decomposition(recut);
    }
    stepper.step(dt);
  }
  bool owned_once = true;
  for (int k = 0; k < parts; ++k) {
    const Subdomain& sd = stepper.subdomain(k);
    const Particles& p = systems[k]->particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (sd.is_ghost(i)) continue;
      owned_once = owned_once && out.state.count(p.id[i]) == 0;
      out.state[p.id[i]] = {p.position[i], p.velocity[i], p.angular_velocity[i]};
    }
    out.migrated += sd.migrated_in();
    out.ghosts_at_end += sd.ghost_count();
  }
  REQUIRE(owned_once);  // every particle in one subdomain
  out.kinetic = stepper.kinetic_energy();
  out.momentum = stepper.linear_momentum();
  out.elastic = stepper.elastic_energy();
  out.wall = stepper.wall_force(0);
  for (int k = 0; k < parts; ++k) {
    out.system_wall += systems[k]->wall_force(0);
    for (int face = 0; face < 6; ++face) out.face_scale += systems[k]->wall_face_force(0, face)->norm();
    out.system_kinetic += systems[k]->kinetic_energy();
    out.system_elastic += systems[k]->elastic_energy();
  }
  out.builds = stepper.builds();
  out.steps = stepper.steps();
  out.fused_steps = stepper.fused_steps();
  if (recut_at > 0) {  // the re-cut was taken up (at a list build after it)
    bool taken = false;
    for (int k = 0; k < parts; ++k) {
      const DomainDecomposition::Box& box = stepper.decomposition().box(k);
      taken = taken || box.lo != d.box(k).lo || box.hi != d.box(k).hi;
    }
    out.recut = out.recut && taken;
  }
  return out;
}

std::size_t differing(const Run& a, const Run& ref) { return test::differing(a.state, ref.state); }

constexpr long kSteps = 300;

// one subdomain, every step on the exact path (the splits take the fused one where they can)
const Run& reference() {
  SubdomainStepper::Options exact;
  exact.fused = false;
  static const Run r = run_split(1, kSteps, exact);
  return r;
}

}  // namespace

TEST_CASE("dem: subdomains: a split bed steps to the bits of one subdomain on the exact path, on 1 to 4 and fused",
          "[dem][subdomains]") {
  const Run& ref = reference();
  REQUIRE(ref.state.size() == static_cast<std::size_t>(bed().x.rows()));
  REQUIRE(ref.state.size() > 1000);
  REQUIRE(ref.builds >= 4);  // several list builds over the run
  REQUIRE(ref.migrated == 0);
  // the particles moved: not the start's positions
  std::size_t moved = 0;
  for (const auto& [id, s] : ref.state)
    moved += (s.x - bed().x.row(id).transpose()).norm() > kSkin ? 1 : 0;
  REQUIRE(moved > ref.state.size() / 2);
  REQUIRE(ref.fused_steps == 0);
  for (const int parts : {1, 2, 3, 4}) {
    CAPTURE(parts);
    const Run split = run_split(parts, kSteps);
    // most steps on the fused path (the exact one near a build and after it)
    CHECK(split.fused_steps > split.steps / 2);
    CHECK(split.builds == ref.builds);
    if (parts > 1) {
      CHECK(split.migrated > 0);  // particles crossed the cuts
      CHECK(split.ghosts_at_end > 0);
    }
    CHECK(differing(split, ref) == 0);
    // the exact sums over the owned particles: the same bits
    CHECK(split.kinetic == ref.kinetic);
    CHECK(split.momentum == ref.momentum);
    CHECK(split.elastic == ref.elastic);
    CHECK(split.wall == ref.wall);
    // each System's own sum counts its ghosts too
    if (parts > 1) CHECK(split.system_kinetic > ref.kinetic);
  }
  // and on another number of threads (each subdomain's force pass is thread-count independent)
  const int threads = max_threads();
  set_num_threads(threads == 1 ? 2 : 1);
  const Run other_threads = run_split(3, kSteps);
  set_num_threads(threads);
  CHECK(differing(other_threads, ref) == 0);
  // the exact sum against the ordered one of one System (no ghosts): rounding apart
  CHECK(ref.kinetic > 0.0);
  CHECK(std::abs(ref.kinetic - ref.system_kinetic) <= 1e-12 * ref.kinetic);
  CHECK(ref.elastic > 0.0);
  CHECK(std::abs(ref.elastic - ref.system_elastic) <= 1e-12 * ref.elastic);
  // the walls: touched, and the exact sum against the block sums of one System (rounding apart)
  CHECK(ref.face_scale > 0.0);
  CHECK((ref.wall - ref.system_wall).norm() <= 1e-12 * ref.face_scale);
}

TEST_CASE("dem: subdomains: without ghosts the split differs (the comparison can fail)",
          "[dem][subdomains]") {
  SubdomainStepper::Options no_ghosts;
  no_ghosts.ghost_distance = 0.0;
  const Run split = run_split(2, kSteps, no_ghosts);
  CHECK(split.ghosts_at_end == 0);
  CHECK(differing(split, reference()) > 0);
}

TEST_CASE("dem: subdomains: without the histories of the ghosts' pairs the split differs",
          "[dem][subdomains]") {
  const Run split = run_split(2, kSteps, {}, 0, true);
  CHECK(split.ghosts_at_end > 0);
  CHECK(differing(split, reference()) > 0);
}

TEST_CASE("dem: subdomains: a re-cut in the middle of the run keeps the bits",
          "[dem][subdomains]") {
  const Run split = run_split(3, kSteps, {}, kSteps / 2);
  CHECK(split.recut);
  CHECK(differing(split, reference()) == 0);
}

TEST_CASE("dem: subdomains: bad set-ups and messages are refused", "[dem][subdomains]") {
  InProcessTransport transport(2);
  const DomainDecomposition d = DomainDecomposition::bisection({}, kLo, kHi, 2);
  auto a = subdomain_system({0, 1});
  CHECK_THROWS_AS(SubdomainStepper({a.get()}, transport, d, kSkin), Error);
  CHECK_THROWS_AS(InProcessTransport(0), Error);
  CHECK_THROWS_AS(GlobalOrder(kLo, kHi, 0.0), Error);
  // a message that is not a build's
  auto b = subdomain_system({2, 3});
  Subdomain sd(*b, 1, 2);
  GlobalOrder order(kLo, kHi, 1e-3);
  SubdomainMail in(2);
  in[0] = std::vector<std::byte>(12, std::byte{7});
  CHECK_THROWS_AS(sd.unpack_moves(in, order, d, 1e-3), Error);
  CHECK(b->particle_count() == 2);
}

TEST_CASE("dem: exact sums: the exact sum rounded once, in any order and split", "[dem][subdomains]") {
  // cancellation an ordered sum loses
  ExactSum a;
  for (const double x : {1e16, 1.0, -1e16}) a.add(x);
  CHECK(a.value() == 1.0);
  // ten times 0.1: the exact sum 10 * 0.1000000000000000055511151231257827 rounds to 1
  ExactSum b;
  double naive = 0.0;
  for (int k = 0; k < 10; ++k) b.add(0.1), naive += 0.1;
  CHECK(naive != 1.0);
  CHECK(b.value() == 1.0);
  // no overflow in between; negative results; the smallest subnormal; zero
  ExactSum c;
  for (const double x : {1e308, 1e308, -1e308}) c.add(x);
  CHECK(c.value() == 1e308);
  ExactSum d;
  for (const double x : {-3.5, 1.25, 4.9e-324}) d.add(x);
  CHECK(d.value() == -2.25);
  ExactSum e;
  e.add(4.9e-324);
  CHECK(e.value() == 4.9e-324);
  ExactSum z;
  z.add(2.0), z.add(-2.0);
  CHECK(z.value() == 0.0);
  ExactSum inf;
  inf.add(1.0), inf.add(std::numeric_limits<double>::infinity());
  CHECK(std::isinf(inf.value()));
  // terms of mixed signs and magnitudes: the same bits in reverse order and summed in three
  // parts merged (through bytes) in another order
  std::vector<double> terms;
  std::uint64_t h = 12345;
  for (int k = 0; k < 5000; ++k) {
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    const double mant = static_cast<double>(h >> 11) / 9007199254740992.0 - 0.5;
    terms.push_back(std::ldexp(mant, static_cast<int>(h % 80) - 40));
  }
  ExactSum forward, backward, parts[3];
  for (const double x : terms) forward.add(x);
  for (auto it = terms.rbegin(); it != terms.rend(); ++it) backward.add(*it);
  for (std::size_t k = 0; k < terms.size(); ++k) parts[k % 3].add(terms[k]);
  std::vector<std::byte> bytes(ExactSum::byte_size);
  ExactSum merged, copy;
  for (const int k : {2, 0, 1}) {
    parts[k].write(bytes.data());
    copy.read(bytes.data());
    merged.add(copy);
  }
  CHECK(forward.value() == backward.value());
  CHECK(merged.value() == forward.value());
  // the compact form carries the same sum in fewer bytes where few limbs are in use, and
  // refuses bytes cut short
  for (const ExactSum* x : {&forward, &a, &z}) {
    std::vector<std::byte> compact(x->compact_size());
    x->write_compact(compact.data());
    ExactSum back;
    CHECK(back.read_compact(compact.data(), compact.size()) == compact.size());
    CHECK(back.value() == x->value());
    CHECK(back.read_compact(compact.data(), compact.size() - 1) == 0);
  }
  ExactSum force;  // terms of one magnitude (a vertex's force): a few limbs
  for (int k = 1; k <= 100; ++k) force.add(0.37 * k);
  CHECK(force.compact_size() <= 18 + 8 * 4);
  // and close to a long double sum (correctly rounded to within the long sum's own error)
  long double sum = 0.0L;
  for (const double x : terms) sum += x;
  CHECK(std::abs(forward.value() - static_cast<double>(sum)) <= 1e-12 * std::abs(static_cast<double>(sum)));
}
