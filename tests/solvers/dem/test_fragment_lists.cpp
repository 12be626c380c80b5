// Fragments taken into the neighbour lists without a search (NeighborList::insert_offspring(),
// System::replace_particles() with local fragment insertion): the lists hold every pair a search
// finds, the particles keep their order, and a crushing bed keeps its physics.

#include "dem_test_helpers.hpp"

#include "partita/dem/breakage.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/parallel.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>

using namespace partita::dem;

namespace {

using PairSet = std::set<std::pair<int, int>>;

PairSet pairs_of(const NeighborList& nl) {
  PairSet s;
  int last_i = -1, last_j = -1;
  bool ordered = true;
  nl.for_each_pair([&](int i, int j) {
    ordered = ordered && i < j && (i > last_i || j > last_j);
    last_i = i, last_j = j;
    s.emplace(i, j);
  });
  CHECK(ordered);  // each pair once, i < j, rows ascending
  CHECK(s.size() == nl.pair_count());
  return s;
}

// Four spheres of radius 0.45 R at 0.54 R from the centre along a tetrahedron's corners (inside:
// 0.54 + 0.45 < 1), turned by `rot`.
std::vector<Eigen::Vector3d> tetra_offsets(double r, const Eigen::Matrix3d& rot) {
  const double a = 0.54 * r / std::sqrt(3.0);
  std::vector<Eigen::Vector3d> c = {{a, a, a}, {a, -a, -a}, {-a, a, -a}, {-a, -a, a}};
  for (auto& v : c) v = rot * v;
  return c;
}

struct Bed {
  Particles p;
  std::vector<TriangleMesh> meshes;
  std::vector<PlaneWall> planes;
};

// A random bed of 0.8 and 1.2 mm spheres in a 12 mm box, a floor plane and a tilted plate mesh
// through the bed's lower part.
Bed make_bed() {
  Bed b;
  const Packing pk = test::two_size_packing(Eigen::Vector3d::Zero(), Eigen::Vector3d(12e-3, 12e-3, 12e-3),
                                            1.2e-3, 0.8e-3, 0.55, 3);
  for (Eigen::Index k = 0; k < pk.positions.rows(); ++k) {
    b.p.position.push_back(pk.positions.row(k).transpose());
    b.p.velocity.push_back(Eigen::Vector3d::Zero());
    b.p.angular_velocity.push_back(Eigen::Vector3d::Zero());
    b.p.force.push_back(Eigen::Vector3d::Zero());
    b.p.torque.push_back(Eigen::Vector3d::Zero());
    b.p.radius.push_back(pk.radii[k]);
    b.p.mass.push_back(1.0);
    b.p.inertia.push_back(1.0);
    b.p.material.push_back(0);
    b.p.id.push_back(k);
  }
  PlaneWall floor;
  floor.point = Eigen::Vector3d::Zero();
  floor.normal = Eigen::Vector3d::UnitZ();
  b.planes.push_back(floor);
  Eigen::MatrixX3d v(4, 3);
  v << -1e-3, -1e-3, 2e-3, 13e-3, -1e-3, 4e-3, 13e-3, 13e-3, 4e-3, -1e-3, 13e-3, 2e-3;
  TriangleMesh::Triangles t(2, 3);
  t << 0, 1, 2, 0, 2, 3;
  b.meshes.emplace_back(v, t, 0);
  return b;
}

// Replaces `parents` of b.p by four fragments each (appended in the parents' order) and returns
// new_of_old; born receives the offspring records.
std::vector<int> split(Bed& b, const std::vector<int>& parents, std::mt19937& rng,
                       std::vector<NeighborList::Offspring>& born) {
  const int n = static_cast<int>(b.p.size());
  std::vector<char> gone(n, 0);
  for (int q : parents) gone[q] = 1;
  Particles out;
  std::vector<int> new_of_old(n, -1);
  auto push = [&](const Eigen::Vector3d& x, double r, std::int64_t id) {
    out.position.push_back(x);
    out.velocity.push_back(Eigen::Vector3d::Zero());
    out.angular_velocity.push_back(Eigen::Vector3d::Zero());
    out.force.push_back(Eigen::Vector3d::Zero());
    out.torque.push_back(Eigen::Vector3d::Zero());
    out.radius.push_back(r);
    out.mass.push_back(1.0);
    out.inertia.push_back(1.0);
    out.material.push_back(0);
    out.id.push_back(id);
  };
  for (int i = 0; i < n; ++i)
    if (!gone[i]) new_of_old[i] = static_cast<int>(out.size()), push(b.p.position[i], b.p.radius[i], b.p.id[i]);
  born.clear();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::int64_t id = 1'000'000 + static_cast<std::int64_t>(b.p.size());
  for (int q : parents) {
    const Eigen::Matrix3d rot =
        Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    for (const Eigen::Vector3d& c : tetra_offsets(b.p.radius[q], rot)) {
      push(b.p.position[q] + c, 0.45 * b.p.radius[q], id++);
      born.push_back({q, c});
    }
  }
  b.p = out;
  return new_of_old;
}

}  // namespace

TEST_CASE("dem: fragments inserted into the lists give the lists a search gives",
          "[dem][breakage][lists]") {
  Bed b = make_bed();
  REQUIRE(b.p.size() > 1000);
  const double skin = 0.15e-3;
  NeighborList nl;
  nl.set_skin(skin);
  nl.build(b.p, b.planes, b.meshes);
  std::mt19937 rng(7);
  // parents: neighbours of one another (a cluster: fragments of neighbouring parents must find
  // each other), some touching the plate mesh or the floor, and scattered ones
  std::vector<int> parents;
  {
    const Eigen::Vector3d centre(6e-3, 6e-3, 6e-3);
    for (int i = 0; i < static_cast<int>(b.p.size()); ++i)
      if ((b.p.position[i] - centre).norm() < 2.5e-3 || i % 97 == 0) parents.push_back(i);
  }
  REQUIRE(parents.size() > 20);
  std::vector<NeighborList::Offspring> born;
  // with the positions at the build (references = positions), the inserted lists are exactly
  // those a new search gives: the kept pairs are the search's, the new ones pass its cut-off
  const int old_n = static_cast<int>(b.p.size());
  std::vector<int> new_of_old = split(b, parents, rng, born);
  const int kept = old_n - static_cast<int>(parents.size());
  nl.insert_offspring(new_of_old, kept, born, b.p);
  NeighborList fresh;
  fresh.set_skin(skin);
  fresh.build(b.p, b.planes, b.meshes);
  const PairSet local = pairs_of(nl), searched = pairs_of(fresh);
  INFO(local.size() << " pairs inserted locally, " << searched.size() << " by a search");
  CHECK(local == searched);
  // the kept pairs keep their histories' slots; the new pairs have none
  {
    int kept_pairs = 0, sources = 0;
    const auto& src = nl.slot_sources();
    int slot = 0;
    nl.for_each_pair([&](int, int j) {
      kept_pairs += j < kept;
      sources += src[slot].slot >= 0;
      ++slot;
    });
    CHECK(sources == kept_pairs);
  }
  // planes and mesh candidates: a fragment has its parent's, a superset of what a search gives
  for (int i = 0; i < static_cast<int>(b.p.size()); ++i) {
    CHECK((fresh.plane_mask(i) & ~nl.plane_mask(i)) == 0);
    for (const MeshCandidate* c = fresh.mesh_candidates_begin(i); c != fresh.mesh_candidates_end(i); ++c) {
      const bool found = std::any_of(nl.mesh_candidates_begin(i), nl.mesh_candidates_end(i),
                                     [&](const MeshCandidate& m) {
                                       return m.mesh == c->mesh && m.triangle == c->triangle;
                                     });
      CHECK(found);
    }
  }
  // A second change after the particles moved (less than skin/2): parents among the fragments of
  // the first. The Verlet guarantee holds: every pair closer than R_i + R_j + skin - 2 d_max at the
  // positions now (d_max: the largest displacement since the build) is listed.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double step = 0.2 * skin;  // |d| <= 0.2 sqrt(3) skin < skin / 2
  for (auto& x : b.p.position) x += step * Eigen::Vector3d(u(rng), u(rng), u(rng));
  std::vector<int> second;
  for (int i = kept; i < static_cast<int>(b.p.size()); i += 3) second.push_back(i);
  for (int i = 5; i < kept; i += 151) second.push_back(i);
  std::sort(second.begin(), second.end());
  const int n1 = static_cast<int>(b.p.size());
  new_of_old = split(b, second, rng, born);
  nl.insert_offspring(new_of_old, n1 - static_cast<int>(second.size()), born, b.p);
  const PairSet after = pairs_of(nl);
  const double d_max = step * std::sqrt(3.0);
  const int n = static_cast<int>(b.p.size());
  long close = 0, missing = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double cut = b.p.radius[i] + b.p.radius[j] + skin - 2.0 * d_max;
      if ((b.p.position[i] - b.p.position[j]).squaredNorm() < cut * cut) {
        ++close;
        missing += after.count({i, j}) == 0;
      }
    }
  INFO(close << " pairs within the guaranteed distance");
  CHECK(close > 1000);
  CHECK(missing == 0);
  // lists not built for the set before the change are refused
  NeighborList none;
  CHECK_THROWS_AS(none.insert_offspring(new_of_old, 0, born, b.p), Error);
}

namespace {

System crushing_bed(double box, bool local) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.0});
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(Eigen::Vector3d(0, 0, 1e-3),
                                            Eigen::Vector3d(box, box, box), 1.2e-3, 0.8e-3, 0.6, 9);
  sys.add_particles(pk.positions, pk.radii, m);
  for (std::size_t i = 0; i < sys.particle_count(); ++i) sys.set_particle_velocity(i, {0, 0, -0.5});
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2 * box), m, 0b011111);
  sys.set_sort_interval(10);
  sys.set_energy_tracking(true);
  sys.set_local_fragment_insertion(local);
  BreakageParameters b;
  b.limit_strength = 0.4e6;
  b.reference_size = 1e-3;
  b.weibull_modulus = 3.0;
  b.comminution_limit = 0.5e-3;
  b.restore_mass = true;
  b.pattern = FragmentPattern::Kind::equal_4;
  sys.add_hook(std::make_unique<Breakage>(b));
  return sys;
}

double total_mass(const System& s) {
  double m = 0.0;
  for (double v : s.particles().mass) m += v;
  return m;
}

}  // namespace

TEST_CASE("dem: a crushing bed with fragments inserted locally: every contact listed, mass and "
          "energy balanced, no search per breakage",
          "[dem][breakage][lists]") {
  auto run = [](bool local, bool check_lists) {
    System sys = crushing_bed(12e-3, local);
    const double m0 = total_mass(sys);
    long unlisted = 0, contacts = 0;
    for (int s = 0; s < 1000; ++s) {
      sys.step(0.2 * sys.rayleigh_time_step());
      if (!check_lists || s % 10 != 0) continue;
      // every touching pair at the end of the step is listed (brute force over all pairs)
      REQUIRE(sys.lists_current());
      PairSet listed;
      sys.neighbor_list().for_each_pair([&](int i, int j) { listed.emplace(i, j); });
      const Particles& p = sys.particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j) {
          const double cut = p.radius[i] + p.radius[j];
          if ((p.position[i] - p.position[j]).squaredNorm() < cut * cut) {
            ++contacts;
            unlisted += listed.count({static_cast<int>(i), static_cast<int>(j)}) == 0;
          }
        }
    }
    struct Result {
      long events, particles, builds, local, contacts, unlisted;
      double mass_error, balance;
    };
    const auto& c = static_cast<const Breakage&>(sys.hook(0)).counters();
    return Result{c.events,
                  static_cast<long>(sys.particle_count()),
                  sys.neighbor_list().build_count(),
                  sys.local_insertions(),
                  contacts,
                  unlisted,
                  std::abs(total_mass(sys) - m0) / m0,
                  sys.energy_balance_error()};
  };
  const auto local = run(true, true);
  const auto searched = run(false, false);
  INFO("local: " << local.events << " events, " << local.particles << " particles, "
                 << local.builds << " list builds, " << local.local << " local insertions, "
                 << local.contacts << " contacts checked, balance error " << local.balance
                 << "; search: " << searched.events << " events, " << searched.builds
                 << " builds, balance error " << searched.balance);
  CHECK(local.events > 150);
  CHECK(local.local > 100);
  CHECK(local.contacts > 3000);
  CHECK(local.unlisted == 0);
  // restored mass: the bed keeps its mass to rounding
  CHECK(local.mass_error < 1e-12);
  // the same bound on the energy balance as the search path (both close it; the fragments' first
  // half step with their parent's accelerations instead of their own forces)
  CHECK(std::abs(searched.balance) < 2e-3);
  CHECK(std::abs(local.balance) < 2e-3);
  // the local path searches only when the particles moved, the search path at every change
  CHECK(searched.builds > 2 * local.builds);
  // the same physics: as many events within the scatter of a chaotic bed (a quarter)
  CHECK(std::abs(local.events - searched.events) < 0.25 * searched.events);
}

TEST_CASE("dem: with fragments inserted locally, results do not depend on the number of threads",
          "[dem][breakage][lists][threads]") {
  auto run = [](int threads) {
    set_num_threads(threads);
    System sys = crushing_bed(14e-3, true);
    for (int s = 0; s < 300; ++s) sys.step(0.2 * sys.rayleigh_time_step());
    return sys;
  };
  const int before = max_threads();
  System one = run(1);
  System two = run(2);
  set_num_threads(before);
  CHECK(one.local_insertions() > 0);
  const Particles& p = one.particles();
  const Particles& q = two.particles();
  CHECK(p.id == q.id);
  CHECK(p.position == q.position);
  CHECK(p.velocity == q.velocity);
  CHECK(one.energies().breakage == two.energies().breakage);
}
