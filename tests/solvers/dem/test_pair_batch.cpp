// The batched pair kernels (pair_batch.hpp) against the scalar kernel (PairContacts::force()):
// on random touching pairs of every branch of the law (both damping models, so both tangential
// caps and the tension clamp; friction off and on, sticking and sliding, a zero history;
// rolling resistance off and on; restitution 1, no damping; coincident centres), every kernel
// set this CPU runs gives the scalar kernel's bits: forces, torques, load and history; with
// yielding particles also the permanent overlaps and the work of their growth.

#include "partita/dem/pair_batch.hpp"
#include "partita/dem/contact_model.hpp"
#include "partita/dem/pair_contacts.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace partita::dem;

namespace {

bool same_bits(const double* a, const double* b, int n) {
  return std::memcmp(a, b, sizeof(double) * static_cast<std::size_t>(n)) == 0;
}

struct Contacts {
  std::vector<PackedParticle> packed;
  std::vector<double> mass;
  std::vector<int> material;
  std::vector<PairTask> tasks;
  std::vector<Eigen::Vector3d> shear;
  // yield (empty: none): per particle the yield pressure, per slot the permanent overlap
  std::vector<double> pressure;
  std::vector<float> plastic;
  double below_diameter = 0.0;
};

// Yielding particles for c: a third below the diameter limit with a yield pressure, some
// pairs with a permanent overlap (below, near and above the present overlap)
void add_yield(Contacts& c, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  c.below_diameter = 2.0e-3;  // radii 0.5..1.5 mm: about half the particles
  for (std::size_t i = 0; i < c.packed.size(); ++i)
    c.pressure.push_back(i % 3 == 2 ? 0.0 : 1.0e6 * (1.0 + 20.0 * unit(rng)));
  for (const PairTask& t : c.tasks) {
    const double overlap = c.packed[t.i].r + c.packed[t.j].r - (c.packed[t.i].x - c.packed[t.j].x).norm();
    const int kind = t.s % 4;
    // (a pair of which neither particle is below the size never yields, so it has no
    // permanent overlap: PairYield)
    const bool can_yield = 2.0 * c.packed[t.i].r < c.below_diameter ||
                           2.0 * c.packed[t.j].r < c.below_diameter;
    c.plastic.push_back(kind == 0 || !can_yield
                            ? 0.0f
                            : static_cast<float>(overlap * (kind == 1 ? 0.3 : kind == 2 ? 0.999 : 1.5)));
  }
}

// n pairs (2k, 2k + 1), each overlapping, in slot k; materials drawn from 0..materials-1
Contacts random_contacts(int n, int materials, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  Contacts c;
  c.packed.resize(2 * static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    PackedParticle& a = c.packed[2 * k];
    PackedParticle& b = c.packed[2 * k + 1];
    a.r = 1e-3 * (0.5 + unit(rng));
    b.r = 1e-3 * (0.5 + unit(rng));
    a.x = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 1e-2;
    const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const double overlap = (k % 17 == 0 ? 0.3 : 0.02 * unit(rng)) * (a.r + b.r);
    b.x = k % 41 == 5 ? a.x : Eigen::Vector3d(a.x - dir * (a.r + b.r - overlap));
    // speeds from creeping to impact: some pairs slide, some pull apart (tension)
    const double speed = k % 3 == 0 ? 1e-4 : (k % 3 == 1 ? 0.1 : 5.0);
    a.v = Eigen::Vector3d(u(rng), u(rng), u(rng)) * speed;
    b.v = Eigen::Vector3d(u(rng), u(rng), u(rng)) * speed;
    a.w = Eigen::Vector3d(u(rng), u(rng), u(rng)) * (k % 5 == 0 ? 0.0 : 100.0 * speed);
    b.w = k % 5 == 0 ? a.w : Eigen::Vector3d(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 100.0);
    a.f = b.f = a.t = b.t = Eigen::Vector3d::Zero();
    c.tasks.push_back({k, 2 * k, 2 * k + 1});
    // histories: zero, small (sticking) or large (sliding)
    const double h = k % 4 == 0 ? 0.0 : (k % 4 == 1 ? 1e-9 : 1e-4);
    c.shear.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)) * h);
  }
  for (const PackedParticle& q : c.packed) {
    c.mass.push_back(2500.0 * 4.0 / 3.0 * 3.14159 * q.r * q.r * q.r);
    c.material.push_back(static_cast<int>(rng() % static_cast<unsigned>(materials)));
  }
  return c;
}

ContactModel model_with(DampingModel damping) {
  ContactModel m;
  m.add_material({2.0e8, 0.23, 2500.0});
  m.add_material({7.0e10, 0.3, 7800.0});
  m.add_material({1.0e7, 0.45, 1100.0});
  m.set_interaction(0, 0, {0.3, 0.5, 0.0});
  m.set_interaction(0, 1, {0.0, 0.8, 0.0});   // frictionless
  m.set_interaction(0, 2, {0.5, 1.0, 0.05});  // no damping, rolling resistance
  m.set_interaction(1, 1, {0.2, 0.3, 0.1});
  m.set_interaction(1, 2, {0.6, 0.6, 0.0});
  m.set_interaction(2, 2, {0.4, 0.9, 0.02});
  m.set_damping_model(damping);
  m.update();
  return m;
}

template <bool Load>
void check_against_scalar(const ContactModel& model, const Contacts& c, bool update_history,
                          const PairBatchKernels& set) {
  const int n = static_cast<int>(c.tasks.size());
  const double dt = 1e-6;
  // the scalar kernel
  std::vector<Eigen::Vector3d> shear_scalar = c.shear;
  std::vector<float> plastic_scalar = c.plastic;
  const bool yields = !c.pressure.empty();
  std::vector<PairForce> expected(static_cast<std::size_t>(n));
  std::vector<double> work_scalar(static_cast<std::size_t>(n), 0.0);
  int yielded = 0;
  for (int k = 0; k < n; ++k) {
    const PairTask& t = c.tasks[k];
    char touching = 0;
    Eigen::Vector3d f = Eigen::Vector3d::Zero(), ti = f, tj = f;
    double load = 0.0;
    double p_y = 0.0;
    if (yields)
      p_y = pair_yield_pressure(2.0 * c.packed[t.i].r < c.below_diameter ? c.pressure[t.i] : 0.0,
                                2.0 * c.packed[t.j].r < c.below_diameter ? c.pressure[t.j] : 0.0);
    const bool touch = PairContacts::force<Load>(
        model, c.packed[t.i], c.packed[t.j], c.mass[t.i], c.mass[t.j], c.material[t.i],
        c.material[t.j], shear_scalar[t.s], touching, dt, update_history, f, ti, tj, load,
        yields ? &plastic_scalar[t.s] : nullptr, p_y, &work_scalar[k]);
    REQUIRE(touch);
    yielded += work_scalar[k] > 0.0 ? 1 : 0;
    PairForce& e = expected[k];
    for (int a = 0; a < 3; ++a) e.f[a] = f[a], e.ti[a] = ti[a], e.tj[a] = tj[a];
    e.load = load;
  }
  if (yields && update_history) CHECK(yielded > n / 10);  // the yield branch is exercised
  // the batch, in pieces of every length up to 2 x lanes + 1 (partly filled vectors); the
  // kernels with the energy parts give the same forces
  for (const bool with_energy : {false, true}) {
  std::vector<Eigen::Vector3d> shear_batch = c.shear;
  std::vector<float> plastic_batch = c.plastic;
  const PairYield yield{c.pressure.data(), c.below_diameter, plastic_batch.data()};
  std::vector<PairForce> got(static_cast<std::size_t>(n));
  std::vector<PairEnergy> energy(static_cast<std::size_t>(n));
  const PairBatchKernel kernel = with_energy ? (Load ? set.with_load_energy : set.plain_energy)
                                             : (Load ? set.with_load : set.plain);
  for (int k = 0, piece = 1; k < n; k += piece, piece = piece % (2 * set.lanes + 1) + 1) {
    const int m = std::min(piece, n - k);
    kernel(c.tasks.data() + k, m, c.packed.data(), c.mass.data(), c.material.data(), model,
           shear_batch.data(), dt, update_history, got.data() + k, energy.data() + k,
           yields ? &yield : nullptr);
  }
  int differ = 0;
  for (int k = 0; k < n; ++k) {
    const bool same = same_bits(expected[k].f, got[k].f, 3) &&
                      same_bits(expected[k].ti, got[k].ti, 3) &&
                      same_bits(expected[k].tj, got[k].tj, 3) &&
                      (!Load || same_bits(&expected[k].load, &got[k].load, 1)) &&
                      same_bits(shear_scalar[k].data(), shear_batch[k].data(), 3) &&
                      plastic_scalar == plastic_batch &&
                      (!with_energy || !yields || same_bits(&work_scalar[k], &energy[k].plastic, 1));
    if (!same && ++differ <= 3)
      UNSCOPED_INFO("pair " << k << " differs: f " << expected[k].f[0] << " / " << got[k].f[0]);
  }
  CHECK(differ == 0);
  }
}

}  // namespace

TEST_CASE("dem: the batched pair kernels give the scalar kernel's bits", "[dem][pair-batch]") {
  const PairBatchKernels* sets[4];
  const int count = pair_batch_kernel_sets(sets, 4);
  REQUIRE(count >= 1);
  CHECK(std::string(sets[count - 1]->name) == "sse2");  // the portable set is always there
  std::mt19937_64 rng(2026);
  for (DampingModel damping : {DampingModel::calibrated, DampingModel::liggghts}) {
    const ContactModel model = model_with(damping);
    for (int materials : {1, 3}) {
      const Contacts c = random_contacts(997, materials, rng);
      for (int s = 0; s < count; ++s) {
        INFO("kernel set " << sets[s]->name << ", " << materials << " material(s), damping "
                           << (damping == DampingModel::liggghts ? "liggghts" : "calibrated"));
        for (bool update : {true, false}) {
          check_against_scalar<false>(model, c, update, *sets[s]);
          check_against_scalar<true>(model, c, update, *sets[s]);
        }
        Contacts yielding = c;
        add_yield(yielding, rng);
        for (bool update : {true, false}) {
          INFO("with yielding particles");
          check_against_scalar<false>(model, yielding, update, *sets[s]);
          check_against_scalar<true>(model, yielding, update, *sets[s]);
        }
      }
    }
  }
}

TEST_CASE("dem: the pair kernel set in use is the widest the CPU runs, or the one asked for",
          "[dem][pair-batch]") {
  const PairBatchKernels* sets[4];
  const int count = pair_batch_kernel_sets(sets, 4);
  const PairBatchKernels& used = pair_batch_kernels();
  const char* forced = std::getenv("PARTITA_DEM_PAIR_KERNELS");
  bool available = false;
  for (int s = 0; s < count; ++s)
    available = available || (forced != nullptr && std::string(sets[s]->name) == forced);
  if (forced != nullptr && available)
    CHECK(std::string(used.name) == forced);
  else
    CHECK(&used == sets[0]);
  CHECK(used.lanes >= 2);
}
