// The particle lifecycle: one store for every per-particle array (add, remove, permute, save,
// restore together), stable ids, histories that follow their particles, and the binary state
// (write -> read -> continue is bit-identical to never stopping).

#include "dem_test_helpers.hpp"
#include "partita/dem/parallel.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/particle_store.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <sstream>

using namespace partita::dem;

namespace {

// A bed in a box with a triangulated bump, friction and rolling friction: every kind of history
// (pairs, planes, mesh features) is present once it has settled a little.
System bed(double box = 6e-3, std::uint64_t seed = 5) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.05});
  sys.set_gravity({0, 0, -9.81});
  const Packing pk = test::two_size_packing(
      Eigen::Vector3d(0, 0, 1e-3), Eigen::Vector3d(box, box, box), 1.2e-3, 0.8e-3, 0.6, seed);
  sys.add_particles(pk.positions, pk.radii, m);
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(box, box, 2 * box), m, 0b001111);
  Eigen::MatrixX3d v(5, 3);
  v << 0, 0, 0, box, 0, 0, box, box, 0, 0, box, 0, 0.5 * box, 0.5 * box, 0.1 * box;
  TriangleMesh::Triangles t(4, 3);
  t << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  sys.add_mesh(v, t, m);
  return sys;
}

// Everything a step reads or writes, by id: equal maps mean the same state in any numbering.
struct Snapshot {
  std::map<std::int64_t, std::vector<double>> by_id;
  Eigen::MatrixX3d vertex_forces;
  Eigen::Vector3d wall_force;
  double time = 0.0;
  explicit Snapshot(const System& s) {
    const Particles& p = s.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      std::vector<double>& v = by_id[p.id[i]];
      for (const auto* a : {&p.position, &p.velocity, &p.angular_velocity, &p.force, &p.torque})
        for (int k = 0; k < 3; ++k) v.push_back((*a)[i][k]);
      v.push_back(p.radius[i]);
      v.push_back(p.mass[i]);
      v.push_back(p.inertia[i]);
      v.push_back(p.material[i]);
    }
    vertex_forces = s.vertex_forces(0);
    wall_force = s.wall_force(0);
    time = s.time();
  }
  bool operator==(const Snapshot& o) const {
    return by_id == o.by_id && vertex_forces == o.vertex_forces && wall_force == o.wall_force &&
           time == o.time;
  }
};

double largest_force_difference(const System& a, const System& b) {
  std::map<std::int64_t, Eigen::Vector3d> fa;
  for (std::size_t i = 0; i < a.particle_count(); ++i)
    fa[a.particles().id[i]] = a.particles().force[i];
  double d = 0.0;
  for (std::size_t i = 0; i < b.particle_count(); ++i)
    d = std::max(d, (fa.at(b.particles().id[i]) - b.particles().force[i]).norm());
  return d;
}

std::vector<int> random_permutation(std::size_t n, std::mt19937_64& rng) {
  std::vector<int> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<int>(k);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

}  // namespace

TEST_CASE("dem: particle store: 10^3 random adds, removals and permutations keep every array",
          "[dem][lifecycle]") {
  // Reference: a map id -> values, updated by the same operations independently of the store.
  ParticleStore store;
  const int h_vec = store.add_array<Eigen::Vector3d>("history", 3, Eigen::Vector3d::Constant(-1));
  const int h_int = store.add_array<std::int64_t>("tag", 1, std::int64_t{7});
  std::map<std::int64_t, std::pair<double, std::int64_t>> ref;  // id -> (radius, tag)
  std::mt19937_64 rng(42);
  std::set<std::int64_t> ever;
  std::vector<char> flags;
  std::vector<int> new_of_old;
  for (int op = 0; op < 1000; ++op) {
    const int kind = static_cast<int>(rng() % 3);
    if (kind == 0 || store.size() < 4) {
      const std::size_t i = store.add(rng() % 4 == 0 ? static_cast<std::int64_t>(1000 + op) : -1);
      const std::int64_t id = store.core().id[i];
      CHECK(ever.insert(id).second);  // never an id held before
      store.core().radius[i] = 1.0 + op;
      CHECK(store.array<std::int64_t>(h_int)[i] == 7);  // new particles get the fill value
      store.array<std::int64_t>(h_int)[i] = 3 * id;
      for (int k = 0; k < 3; ++k)
        store.array<Eigen::Vector3d>(h_vec)[3 * i + k] = Eigen::Vector3d::Constant(id + 0.25 * k);
      ref[id] = {1.0 + op, 3 * id};
    } else if (kind == 1) {
      flags.assign(store.size(), 0);
      for (auto& f : flags) f = rng() % 5 == 0;
      for (std::size_t i = 0; i < flags.size(); ++i)
        if (flags[i]) ref.erase(store.core().id[i]);
      store.remove(flags, new_of_old);
    } else {
      store.permute(random_permutation(store.size(), rng));
    }
  }
  auto check_against_reference = [&](const ParticleStore& s) {
    REQUIRE(s.size() == ref.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::int64_t id = s.core().id[i];
      REQUIRE(ref.count(id) == 1);
      CHECK(s.core().radius[i] == ref[id].first);
      CHECK(s.array<std::int64_t>(h_int)[i] == ref[id].second);
      for (int k = 0; k < 3; ++k)
        CHECK(s.array<Eigen::Vector3d>(h_vec)[3 * i + k] ==
              Eigen::Vector3d::Constant(id + 0.25 * k));
      CHECK(s.core().position.size() == s.size());
    }
  };
  check_against_reference(store);
  // written and read into a store with the same arrays: identical
  std::stringstream bytes;
  BinaryWriter w(bytes);
  store.write(w);
  ParticleStore back;
  back.add_array<Eigen::Vector3d>("history", 3, Eigen::Vector3d::Zero());
  back.add_array<std::int64_t>("tag", 1, std::int64_t{0});
  BinaryReader r(bytes);
  back.read(r);
  check_against_reference(back);
  CHECK(back.next_id() == store.next_id());
  // a store without the arrays refuses the bytes
  ParticleStore other;
  std::stringstream again;
  BinaryWriter w2(again);
  store.write(w2);
  BinaryReader r2(again);
  CHECK_THROWS_AS(other.read(r2), Error);
}

TEST_CASE("dem: particle store: a permutation of 40,000 particles on 1 and 2 threads",
          "[dem][lifecycle][threads]") {
  // Large enough for the parallel gather: every array (core and registered, of width 1 and 3)
  // holds after permute() exactly the rows order[k] held before, whatever the number of threads.
  const int before = max_threads();
  const std::size_t n = 40000;
  std::mt19937_64 rng(7);
  const std::vector<int> order = random_permutation(n, rng);
  for (int threads : {1, 2}) {
    set_num_threads(threads);
    ParticleStore store;
    const int h_vec = store.add_array<Eigen::Vector3d>("history", 3, Eigen::Vector3d::Zero());
    const int h_tag = store.add_array<std::int64_t>("tag", 1, std::int64_t{0});
    for (std::size_t i = 0; i < n; ++i) {
      store.add();
      const double x = static_cast<double>(i);
      store.core().position[i] = Eigen::Vector3d(x, -x, 0.5 * x);
      store.core().radius[i] = 1.0 + x;
      store.array<std::int64_t>(h_tag)[i] = 5 * static_cast<std::int64_t>(i) + 1;
      for (int k = 0; k < 3; ++k)
        store.array<Eigen::Vector3d>(h_vec)[3 * i + k] = Eigen::Vector3d::Constant(x + 0.25 * k);
    }
    store.permute(order);
    INFO(threads << " threads");
    std::size_t wrong = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const auto i = static_cast<std::size_t>(order[k]);
      const double x = static_cast<double>(i);
      wrong += store.core().id[k] != static_cast<std::int64_t>(i);
      wrong += store.core().position[k] != Eigen::Vector3d(x, -x, 0.5 * x);
      wrong += store.core().radius[k] != 1.0 + x;
      wrong += store.array<std::int64_t>(h_tag)[k] != 5 * static_cast<std::int64_t>(i) + 1;
      for (int k3 = 0; k3 < 3; ++k3)
        wrong += store.array<Eigen::Vector3d>(h_vec)[3 * k + k3] !=
                 Eigen::Vector3d::Constant(x + 0.25 * k3);
    }
    CHECK(wrong == 0);
  }
  set_num_threads(before);
}

TEST_CASE("dem: particle store: particles packed into bytes and unpacked into another store",
          "[dem][lifecycle][pack]") {
  // Two stores of one layout (as two subdomains of one system have): particles moved as bytes
  // arrive with every array's rows and their ids, in the order asked; the rest is refused.
  const auto make = [] {
    ParticleStore s;
    s.add_array<Eigen::Vector3d>("history", 3, Eigen::Vector3d::Constant(-1));
    s.add_array<std::int64_t>("tag", 1, std::int64_t{7});
    s.add_array<double>("empty_now", 0, 0.0);  // a history per wall plane with no plane yet
    return s;
  };
  ParticleStore from = make(), to = make();
  const int h_vec = from.find("history"), h_tag = from.find("tag");
  const auto fill = [&](ParticleStore& s, std::size_t i, double x) {
    s.core().position[i] = Eigen::Vector3d(x, -x, 0.5 * x);
    s.core().velocity[i] = Eigen::Vector3d(2 * x, 0, 1);
    s.core().radius[i] = 1.0 + x;
    s.core().mass[i] = 3.0 + x;
    s.core().material[i] = static_cast<int>(x) % 3;
    s.array<std::int64_t>(h_tag)[i] = 5 * s.core().id[i] + 1;
    for (int k = 0; k < 3; ++k)
      s.array<Eigen::Vector3d>(h_vec)[3 * i + k] = Eigen::Vector3d::Constant(x + 0.25 * k);
  };
  for (int i = 0; i < 20; ++i) fill(from, from.add(100 + 3 * i), i);
  for (int i = 0; i < 4; ++i) fill(to, to.add(), 50 + i);  // ids 0..3
  REQUIRE(from.layout() == to.layout());
  CHECK(from.packed_bytes_per_particle() ==
        5 * 24 + 3 * 8 + 4 + 8 + 3 * 24 + 8);  // core, history, tag; the empty array none

  const std::vector<int> which = {17, 2, 9, 0};
  std::vector<std::byte> bytes = {std::byte{0xAB}};  // pack() appends
  from.pack(which, bytes);
  REQUIRE(bytes.size() == 1 + which.size() * from.packed_bytes_per_particle());
  const std::size_t first = to.unpack(bytes.data() + 1, bytes.size() - 1);
  CHECK(first == 4);
  REQUIRE(to.size() == 8);
  for (std::size_t k = 0; k < which.size(); ++k) {
    const auto i = static_cast<std::size_t>(which[k]);
    const std::size_t j = first + k;
    CHECK(to.core().id[j] == from.core().id[i]);
    CHECK(to.core().position[j] == from.core().position[i]);
    CHECK(to.core().velocity[j] == from.core().velocity[i]);
    CHECK(to.core().radius[j] == from.core().radius[i]);
    CHECK(to.core().mass[j] == from.core().mass[i]);
    CHECK(to.core().material[j] == from.core().material[i]);
    CHECK(to.array<std::int64_t>(h_tag)[j] == from.array<std::int64_t>(h_tag)[i]);
    for (int c = 0; c < 3; ++c)
      CHECK(to.array<Eigen::Vector3d>(h_vec)[3 * j + c] ==
            from.array<Eigen::Vector3d>(h_vec)[3 * i + c]);
  }
  CHECK(to.core().position[3] == Eigen::Vector3d(53, -53, 26.5));  // its own untouched
  CHECK(to.next_id() == 100 + 3 * 17 + 1);  // above every id it holds: no id handed out twice
  CHECK(to.core().id[to.add()] == 100 + 3 * 17 + 1);

  // all of them in a random order and back in id order: the same bytes as before
  std::mt19937_64 rng(3);
  ParticleStore round = make();
  std::vector<std::byte> all;
  from.pack(random_permutation(from.size(), rng), all);
  round.unpack(all.data(), all.size());
  std::vector<int> by_id(round.size());
  for (std::size_t i = 0; i < round.size(); ++i)
    by_id[static_cast<std::size_t>((round.core().id[i] - 100) / 3)] = static_cast<int>(i);
  round.permute(by_id);
  std::vector<std::byte> a, b;
  std::vector<int> every(from.size());
  for (std::size_t i = 0; i < every.size(); ++i) every[i] = static_cast<int>(i);
  from.pack(every, a);
  round.pack(every, b);
  CHECK(a == b);

  // refused, the store left as it was: a size that is no whole particle, a store of another
  // layout, an index out of range
  const std::size_t size = to.size();
  CHECK_THROWS_AS(to.unpack(bytes.data() + 1, bytes.size() - 2), Error);
  ParticleStore plain;  // the core arrays only: a particle of other bytes
  REQUIRE(plain.layout() != to.layout());
  std::vector<std::byte> short_rows;
  plain.add();
  plain.pack({0}, short_rows);
  CHECK_THROWS_AS(to.unpack(short_rows.data(), short_rows.size()), Error);
  CHECK(to.size() == size);
  // a negative id (bytes that are not particles of this layout): refused after the arrays grew,
  // and the store shrunk back. The ids of 4 particles follow 5 vector, 3 double and one int
  // arrays of 4 rows each.
  std::vector<std::byte> bad(bytes.begin() + 1, bytes.end());
  const std::int64_t negative = -5;
  std::memcpy(bad.data() + 4 * (5 * 24 + 3 * 8 + 4) + 8, &negative, 8);
  CHECK_THROWS_AS(to.unpack(bad.data(), bad.size()), Error);
  CHECK(to.size() == size);
  CHECK(to.array<std::int64_t>(h_tag).size() == size);
  std::vector<std::byte> none;
  CHECK_THROWS_AS(from.pack({0, 20}, none), Error);
  CHECK(none.empty());
}

TEST_CASE("dem: 10^3 random adds, removals and renumberings between steps, then save/restore",
          "[dem][lifecycle]") {
  System sys = bed();
  const double dt = 0.2 * sys.rayleigh_time_step();
  sys.run(800, dt);  // landed: sticking contacts with histories
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::set<std::int64_t> ids_seen;
  for (std::int64_t id : sys.particles().id) ids_seen.insert(id);
  long adds = 0, removals = 0, renumberings = 0;
  for (int op = 0; op < 1000; ++op) {
    const int kind = static_cast<int>(rng() % 4);
    if (kind == 0) {  // a small particle dropped in from above
      const std::size_t i = sys.add_particle(
          {6e-3 * (0.2 + 0.6 * u(rng)), 6e-3 * (0.2 + 0.6 * u(rng)), 8e-3 + 4e-3 * u(rng)},
          2e-4 + 2e-4 * u(rng), 0);
      CHECK(ids_seen.insert(sys.particles().id[i]).second);  // a new id
      ++adds;
    } else if (kind == 1 && sys.particle_count() > 20) {
      std::vector<char> flags(sys.particle_count(), 0);
      flags[rng() % flags.size()] = 1;
      sys.remove_particles(flags);
      ++removals;
    } else if (kind == 2) {
      sys.renumber_particles(random_permutation(sys.particle_count(), rng));
      ++renumberings;
    } else {
      sys.step(std::min(dt, 0.2 * sys.rayleigh_time_step()));
    }
  }
  INFO(adds << " adds, " << removals << " removals, " << renumberings << " renumberings, "
            << sys.particle_count() << " particles");
  // ids stay unique
  std::set<std::int64_t> ids(sys.particles().id.begin(), sys.particles().id.end());
  CHECK(ids.size() == sys.particle_count());

  const double dt2 = 0.2 * sys.rayleigh_time_step();
  const SystemState saved = sys.save_state();
  std::stringstream file;
  sys.write_state(file);
  sys.run(200, dt2);
  const Snapshot reference(sys);
  CHECK(sys.contact_count() > 0);
  // restored in memory: bit-identical
  sys.restore_state(saved);
  sys.run(200, dt2);
  CHECK(Snapshot(sys) == reference);
  // read into a fresh system set up alike (other particles, other count): bit-identical
  System fresh = bed(6e-3, 11);
  REQUIRE(fresh.particle_count() != saved.particle_count());
  fresh.read_state(file);
  CHECK(fresh.particle_count() == saved.particle_count());
  fresh.run(200, dt2);
  CHECK(Snapshot(fresh) == reference);
}

TEST_CASE("dem: histories follow their particles through renumbering and removal",
          "[dem][lifecycle]") {
  System a = bed();
  const double dt = 0.2 * a.rayleigh_time_step();
  a.run(1500, dt);  // settled: friction forces carried by the tangential histories
  // a free particle far above the bed, touching nothing
  a.add_particle({3e-3, 3e-3, 11e-3}, 3e-4, 0);
  a.step(dt);
  System b = a;
  std::mt19937_64 rng(3);
  b.renumber_particles(random_permutation(b.particle_count(), rng));
  std::vector<char> flags(b.particle_count(), 0);
  for (std::size_t i = 0; i < flags.size(); ++i) flags[i] = b.particles().position[i].z() > 10e-3;
  REQUIRE(std::count(flags.begin(), flags.end(), 1) == 1);
  b.remove_particles(flags);  // removing a particle without contacts changes no other force
  b.renumber_particles(random_permutation(b.particle_count(), rng));
  a.step(dt);
  b.step(dt);
  double f_max = 0.0;
  for (const auto& f : a.particles().force) f_max = std::max(f_max, f.norm());
  // sums in another order: equal to round-off; a lost or misplaced history would change the
  // friction forces by a fraction of mu F_n
  CHECK(largest_force_difference(a, b) < 1e-12 * f_max);
  CHECK(a.mesh_force(0).isApprox(b.mesh_force(0), 1e-12));
  CHECK(a.wall_force(0).isApprox(b.wall_force(0), 1e-12));
  CHECK(b.particle_count() + 1 == a.particle_count());
}

TEST_CASE("dem: a state saved right after a removal or a renumbering restores and steps on alike",
          "[dem][lifecycle]") {
  // Breakage removes particles at the end of a step, and the coupling may save its checkpoint
  // right then, before the next step rebuilds the lists: the pair histories must already follow
  // the renumbered pairs (a state whose histories still had the old pair count was refused).
  for (const bool remove : {true, false}) {
    System sys = bed();
    const double dt = 0.2 * sys.rayleigh_time_step();
    sys.run(800, dt);  // landed: sticking contacts with histories
    REQUIRE(sys.contact_count() > 0);
    if (remove) {
      std::vector<char> flags(sys.particle_count(), 0);
      for (std::size_t i = 0; i < flags.size(); i += 7) flags[i] = 1;  // some with contacts
      sys.remove_particles(flags);
    } else {
      std::mt19937_64 rng(13);
      sys.renumber_particles(random_permutation(sys.particle_count(), rng));
    }
    const SystemState saved = sys.save_state();
    std::stringstream file;
    sys.write_state(file);
    sys.run(200, dt);
    const Snapshot reference(sys);
    sys.restore_state(saved);
    sys.run(200, dt);
    CHECK(Snapshot(sys) == reference);
    System fresh = bed();
    fresh.read_state(file);
    fresh.run(200, dt);
    CHECK(Snapshot(fresh) == reference);
  }
}

TEST_CASE("dem: a state stream with a bad magic, another version or cut short is refused",
          "[dem][lifecycle][errors]") {
  System sys = bed();
  sys.run(10, 0.2 * sys.rayleigh_time_step());
  std::stringstream good;
  sys.write_state(good);
  const std::string bytes = good.str();
  {
    std::stringstream s("not a state at all, just text");
    CHECK_THROWS_WITH(sys.read_state(s), Catch::Contains("magic"));
  }
  {
    std::string other = bytes;
    other[8] = static_cast<char>(other[8] + 1);  // the version follows the 8-byte magic
    std::stringstream s(other);
    CHECK_THROWS_WITH(sys.read_state(s), Catch::Contains("format version"));
  }
  for (std::size_t cut : {std::size_t{4}, std::size_t{20}, bytes.size() / 2, bytes.size() - 1}) {
    std::stringstream s(bytes.substr(0, cut));
    CHECK_THROWS_WITH(sys.read_state(s), Catch::Contains("truncated") || Catch::Contains("magic"));
  }
  {  // another set-up: one plane more
    System other = bed();
    other.add_plane({0, 0, -1}, {0, 0, 1}, 0);
    std::stringstream s(bytes);
    CHECK_THROWS_WITH(other.read_state(s), Catch::Contains("does not fit"));
  }
  {  // a second mesh of another size: refused before anything changes
    Eigen::MatrixX3d v3(3, 3), v4(4, 3);
    v3 << 0, 0, -1, 1, 0, -1, 0, 1, -1;
    v4 << 0, 0, -1, 1, 0, -1, 0, 1, -1, 1, 1, -1;
    TriangleMesh::Triangles t1(1, 3), t2(2, 3);
    t1 << 0, 1, 2;
    t2 << 0, 1, 2, 1, 3, 2;
    System three = bed(), four = bed();
    three.add_mesh(v3, t1, 0);
    four.add_mesh(v4, t2, 0);
    three.run(10, 0.2 * three.rayleigh_time_step());
    std::stringstream s;
    three.write_state(s);
    CHECK_THROWS_WITH(four.read_state(s), Catch::Contains("vertex count"));
    CHECK(four.particles().position == bed().particles().position);  // unchanged
    CHECK(four.time() == 0.0);
  }
  std::stringstream s(bytes);
  CHECK_NOTHROW(sys.read_state(s));
}
