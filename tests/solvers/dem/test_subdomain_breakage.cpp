// Crushing on a split bed (SubdomainStepper with a Breakage hook): a polydisperse bed thrown
// about in a box and pressed by a plate mesh, with particles weak enough that hundreds break
// into fragments and the smallest are crushed to powder, steps to the same bits on 1, 2, 3 and 4
// subdomains: the same particles by id (the fragments' ids do not depend on where they were
// born), the same counters (exact sums over the subdomains), the same changes of the stable
// step. Mass is conserved (the fragments carry their parent's, the powder's is counted), every
// id is held once over the split, the energy books close with the breakage booked, and a restart
// written on P subdomains resumes on M with the bits of one written and resumed on 1.

#include "subdomain_test_helpers.hpp"

#include "partita/dem/breakage.hpp"
#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/subdomain.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <set>
#include <sstream>

using namespace partita::dem;

namespace {

constexpr double kWidth = 12e-3, kBedHeight = 8e-3, kBoxHeight = 16e-3;
constexpr double kSkin = 0.1e-3;
constexpr int kCells = 8;
constexpr long kSteps = 400;
const Eigen::Vector3d kLo = Eigen::Vector3d::Zero();
const Eigen::Vector3d kHi(kWidth, kWidth, kBoxHeight);
const Eigen::Vector3d kCutHi(kWidth, kWidth, 13e-3);
// the plate starts just above the bed and goes down fast: it crushes the top of the bed
const test::SaggingPlate kPlate{kWidth, kCells, kBedHeight + 0.2e-3, 2.0, 0.3e-3};

const test::ThrownBed& bed() {
  static const test::ThrownBed b =
      test::thrown_bed(kLo, Eigen::Vector3d(kWidth, kWidth, kBedHeight), 7, 0x9e3779b97f4a7c15ull);
  return b;
}

BreakageParameters weak() {
  BreakageParameters b;
  b.limit_strength = 2.0e6;  // (E = 10 MPa: collisions at a few dm/s and the plate break them)
  b.reference_size = 1.0e-3;
  b.weibull_modulus = 10.0;
  b.comminution_limit = 0.55e-3;  // (the 0.6 mm ones break once, their fragments to powder)
  b.powder = true;
  b.pattern = FragmentPattern::Kind::equal_4;
  b.restore_mass = true;
  b.seed = 11;
  return b;
}

// One subdomain's System, alike on every subdomain: materials, gravity, the box without its
// top, the plate, the breakage model, the particles of `keep` (id = index).
std::unique_ptr<System> subdomain_system(const std::vector<int>& keep) {
  auto sys = test::bed_system(bed(), keep);
  const int m = 0;  // (its material)
  sys->add_box(kLo, kHi, m, 0b011111);
  sys->add_mesh(kPlate.vertices(0.0, 1.0), kPlate.triangles(), m);
  sys->add_hook(std::make_unique<Breakage>(weak()));
  return sys;
}

std::vector<Eigen::Vector3d> start_positions() { return test::positions(bed()); }

double start_mass() {
  double m = 0.0;
  for (Eigen::Index i = 0; i < bed().r.size(); ++i)
    m += 2500.0 * 4.0 / 3.0 * M_PI * std::pow(bed().r[i], 3);
  return m;
}

struct Run {
  test::MotionById state;
  std::vector<double> counters;  // Breakage::sums() over the split
  long replacement_steps = 0;
  double owned_mass = 0.0;
  std::size_t owned = 0, distinct_ids = 0;
  std::vector<double> dt;  // the steps taken (0.25 of the split's Rayleigh step)
  System::Energies energies;
  double balance = 0.0;
};

struct Plan {
  bool energy = false;
  long restart_at = 0;
  int restart_parts = 1;
};

Run run_split(int parts, const Plan& plan = {}) {
  DomainDecomposition d = DomainDecomposition::bisection(start_positions(), kLo, kCutHi, parts);
  const std::vector<std::vector<int>> keep = test::owned_at(d, start_positions());
  auto [systems, raw] = test::make_systems(parts, [&](int k) { return subdomain_system(keep[k]); });
  auto transport = std::make_unique<InProcessTransport>(parts);
  auto stepper = std::make_unique<SubdomainStepper>(raw, *transport, d, kSkin);
  stepper->set_energy_accounting(plan.energy);
  Run out;
  double t = 0.0;
  const double t_end = kSteps * 0.25 * raw[0]->rayleigh_time_step();
  for (long s = 0; s < kSteps; ++s) {
    if (plan.restart_at > 0 && s == plan.restart_at) {
      std::stringstream file;
      SplitRestart::gather(*stepper).write(file);
      const SplitRestart restart = SplitRestart::read(file);
      parts = plan.restart_parts;
      test::SplitSystems next = test::make_systems(parts, [](int) { return subdomain_system({}); });
      raw = next.raw;
      restart.restore(raw);
      const Particles& p = raw[0]->particles();
      const std::vector<Eigen::Vector3d> x(p.position.begin(), p.position.end());
      auto next_transport = std::make_unique<InProcessTransport>(parts);
      stepper = std::make_unique<SubdomainStepper>(
          raw, *next_transport, DomainDecomposition::bisection(x, kLo, kCutHi, parts), kSkin);
      systems = std::move(next.systems);
      transport = std::move(next_transport);
      stepper->set_energy_accounting(plan.energy);
      stepper->resume();
      if (plan.energy) stepper->restore_books(restart.books());
    }
    // (before the first step the stepper has not looked at the particles yet)
    const double dt = 0.25 * (s == 0 ? raw[0]->rayleigh_time_step() : stepper->rayleigh_time_step());
    t += dt;
    for (System* sys : raw) sys->set_vertex_positions(0, kPlate.vertices(t, t_end));
    stepper->step(dt);
    out.dt.push_back(dt);
  }
  std::set<std::int64_t> ids;
  for (int k = 0; k < parts; ++k) {
    const Subdomain& sd = stepper->subdomain(k);
    const Particles& p = sd.system().particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (sd.is_ghost(i)) continue;
      out.state[p.id[i]] = {p.position[i], p.velocity[i], p.angular_velocity[i]};
      out.owned_mass += p.mass[i];
      ++out.owned;
      ids.insert(p.id[i]);
    }
  }
  out.distinct_ids = ids.size();
  out.counters = stepper->hook_sums(0);
  out.replacement_steps = stepper->replacement_steps();
  if (plan.energy) {
    out.energies = stepper->energies();
    out.balance = stepper->energy_balance_error();
  }
  return out;
}

const Run& reference() {
  static const Run r = run_split(1);
  return r;
}

}  // namespace

TEST_CASE("dem: subdomains: a crushing bed steps to the same bits on 1, 2, 3 and 4 subdomains",
          "[dem][subdomain][breakage]") {
  const Run& ref = reference();
  const BreakageCounters c = Breakage::counters_from(ref.counters);
  INFO("broken " << c.events << ", fragments " << c.fragments << ", powder " << c.powder_events
                 << ", steps with a change " << ref.replacement_steps << ", particles at the end "
                 << ref.owned);
  REQUIRE(c.events >= 50);         // (a crushing bed: the test shows something)
  REQUIRE(c.powder_events >= 5);   // (both kinds of change)
  REQUIRE(c.fragments == 4 * c.events);
  REQUIRE(ref.dt.back() < ref.dt.front());  // fragments lowered the stable step
  // every id once, the mass kept (fragments carry their parent's) or counted (powder)
  CHECK(ref.distinct_ids == ref.owned);
  CHECK(ref.owned == static_cast<std::size_t>(bed().r.size()) + 3 * c.events - c.powder_events);
  CHECK(std::abs(ref.owned_mass + c.powder_mass - start_mass()) <= 1e-12 * start_mass());
  for (const int parts : {2, 3, 4}) {
    const Run r = run_split(parts);
    INFO(parts << " subdomains");
    CHECK(test::differing(r.state, ref.state) == 0);
    CHECK(r.counters == ref.counters);
    CHECK(r.replacement_steps == ref.replacement_steps);
    CHECK(r.dt == ref.dt);
    CHECK(r.distinct_ids == r.owned);
  }
}

TEST_CASE("dem: subdomains: the energy books of a crushing split bed close with the breakage "
          "booked, the same on any split",
          "[dem][subdomain][breakage]") {
  Plan plan;
  plan.energy = true;
  const Run one = run_split(1, plan);
  INFO("breakage booked " << one.energies.breakage << " J, balance " << one.balance);
  CHECK(one.energies.breakage > 0.0);
  CHECK(std::abs(one.balance) < 2e-3);
  // (the books do not change the stepping)
  CHECK(test::differing(one.state, reference().state) == 0);
  const Run three = run_split(3, plan);
  CHECK(three.energies.breakage == one.energies.breakage);
  CHECK(three.energies.damping == one.energies.damping);
  CHECK(three.balance == one.balance);
}

TEST_CASE("dem: subdomains: a crushing bed's restart written on P subdomains resumes on M with "
          "the same bits",
          "[dem][subdomain][breakage]") {
  Plan plan;
  plan.energy = true;
  plan.restart_at = kSteps / 2;
  plan.restart_parts = 1;
  const Run ref = run_split(1, plan);
  REQUIRE(ref.counters[0] > 0.0);
  for (const auto& [p, m] : {std::pair{2, 3}, std::pair{4, 2}}) {
    plan.restart_parts = m;
    const Run r = run_split(p, plan);
    INFO("written on " << p << ", resumed on " << m);
    CHECK(test::differing(r.state, ref.state) == 0);
    CHECK(r.counters == ref.counters);
    CHECK(r.energies.breakage == ref.energies.breakage);
    CHECK(r.balance == ref.balance);
  }
}
