// Particles moved between Systems (the subdomains of a DEM spread over processes) with everything
// they carry: pair histories keyed by particle ids, plane and mesh contact histories, breakage
// state; and the messages that must be refused.

#include "dem_test_helpers.hpp"

#include "partita/dem/breakage.hpp"
#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/error.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <map>
#include <sstream>

using namespace partita::dem;

namespace {

constexpr double kBox = 6e-3;

// A bed under gravity in a box (four side planes, open top) on a pyramid mesh floor: pairs,
// planes and mesh features with friction. `filled` = false: the same set-up without particles
// (a receiving subdomain's).
System bed(bool filled) {
  System sys;
  const int m = sys.add_material({1.0e7, 0.3, 2500.0});
  sys.add_interaction(m, m, {0.4, 0.5, 0.05});
  sys.set_gravity({0, 0, -9.81});
  sys.set_skin(0.1 * 0.6e-3);
  if (filled) {
    const Packing pk = test::two_size_packing(
        Eigen::Vector3d(0, 0, 1e-3), Eigen::Vector3d(kBox, kBox, kBox), 1.2e-3, 0.8e-3, 0.6, 5);
    sys.add_particles(pk.positions, pk.radii, m);
  }
  sys.add_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(kBox, kBox, 2 * kBox), m, 0b001111);
  Eigen::MatrixX3d v(5, 3);
  v << 0, 0, 0, kBox, 0, 0, kBox, kBox, 0, 0, kBox, 0, 0.5 * kBox, 0.5 * kBox, 0.1 * kBox;
  TriangleMesh::Triangles t(4, 3);
  t << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  sys.add_mesh(v, t, m);
  return sys;
}

// index of each id
std::map<std::int64_t, std::size_t> index_by_id(const System& s) {
  std::map<std::int64_t, std::size_t> m;
  for (std::size_t i = 0; i < s.particle_count(); ++i) m[s.particles().id[i]] = i;
  return m;
}

// the same id, position, velocity and angular velocity to the bit, particle by particle through
// the ids
bool same_by_id(const System& a, const System& b) {
  if (a.particle_count() != b.particle_count()) return false;
  const auto at = index_by_id(b);
  const Particles& p = a.particles();
  const Particles& q = b.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto it = at.find(p.id[i]);
    if (it == at.end()) return false;
    const std::size_t j = it->second;
    if (p.position[i] != q.position[j] || p.velocity[i] != q.velocity[j] ||
        p.angular_velocity[i] != q.angular_velocity[j])
      return false;
  }
  return true;
}

// A message of System::pack_particles() without its pair records (header: 41 bytes; the
// particle count at byte 16, the record count at 24; records of PairContacts::record_bytes after the particles).
std::vector<std::byte> without_pair_records(const std::vector<std::byte>& m, std::size_t row) {
  std::uint64_t n = 0, records = 0;
  std::memcpy(&n, m.data() + 16, 8);
  std::memcpy(&records, m.data() + 24, 8);
  const std::size_t pairs_at = 41 + n * row;
  std::vector<std::byte> out(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(pairs_at));
  out.insert(out.end(), m.begin() + static_cast<std::ptrdiff_t>(pairs_at + records * PairContacts::record_bytes), m.end());
  const std::uint64_t none = 0;
  std::memcpy(out.data() + 24, &none, 8);
  return out;
}

std::string state_bytes(const System& s) {
  std::ostringstream out(std::ios::binary);
  s.write_state(out);
  return out.str();
}

}  // namespace

TEST_CASE(
    "dem: a bed split in two by bisection and merged back in another order steps on as if "
    "never moved",
    "[dem][migration]") {
  System whole = bed(true);
  const double dt = 0.2 * whole.rayleigh_time_step();
  whole.run(8000, dt);  // fallen onto the pyramid: lasting contacts with springs
  const std::size_t n = whole.particle_count();
  REQUIRE(n > 100);

  // split by the owners of a bisection in two
  const DomainDecomposition dd =
      DomainDecomposition::bisection(whole.particles().position, Eigen::Vector3d::Zero(),
                                     Eigen::Vector3d(kBox, kBox, 2 * kBox), 2);
  std::vector<int> mine[2];
  for (std::size_t i = 0; i < n; ++i)
    mine[dd.owner(whole.particles().position[i])].push_back(static_cast<int>(i));
  REQUIRE(!mine[0].empty());
  REQUIRE(!mine[1].empty());
  System part[2] = {bed(false), bed(false)};
  std::vector<std::byte> message;
  for (int k = 0; k < 2; ++k) {
    message.clear();
    whole.pack_particles(mine[k], message);
    CHECK(part[k].unpack_particles(message.data(), message.size()) == 0);
    CHECK(part[k].particle_count() == mine[k].size());
    CHECK(part[k].waiting_pair_histories() > 0);  // springs travelled with their particles
  }

  // merged back: the second part first, each in reverse order, in two messages; and the same
  // without the pair histories (to show that they matter)
  System merged = bed(false), bare = bed(false);
  for (const int k : {1, 0}) {
    std::vector<int> all(part[k].particle_count());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(all.size() - 1 - i);
    message.clear();
    part[k].pack_particles(all, message);
    merged.unpack_particles(message.data(), message.size());
    const std::vector<std::byte> springless =
        without_pair_records(message, whole.store().packed_bytes_per_particle());
    bare.unpack_particles(springless.data(), springless.size());
  }
  CHECK(bare.waiting_pair_histories() == 0);
  REQUIRE(merged.particle_count() == n);
  // pairs across the cut came in both messages; pairs inside a part in one
  CHECK(merged.waiting_pair_histories() ==
        part[0].waiting_pair_histories() + part[1].waiting_pair_histories());
  REQUIRE(same_by_id(whole, merged));

  // The force pass sums each particle's contacts in the order of the particle indices, so the
  // bits match where both number the particles alike: (1) the merged system renumbered by id
  // (the whole bed's numbering) against the whole bed; (2) the whole bed renumbered as the
  // merged system holds them against the merged system. The springs go into their pairs' slots
  // at the first step's list build, many with the order of the pair flipped.
  System by_id = merged;
  {
    std::vector<int> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return by_id.particles().id[a] < by_id.particles().id[b]; });
    by_id.renumber_particles(order);
  }
  bare.renumber_particles([&] {
    std::vector<int> order(n);
    for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<int>(k);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return bare.particles().id[a] < bare.particles().id[b]; });
    return order;
  }());
  System renumbered = whole;
  {
    const auto at = index_by_id(whole);
    std::vector<int> order(n);
    for (std::size_t k = 0; k < n; ++k)
      order[k] = static_cast<int>(at.at(merged.particles().id[k]));
    renumbered.renumber_particles(order);
  }
  const long builds = whole.neighbor_list().build_count();
  for (int k = 0; k < 4; ++k) {
    whole.run(100, dt);
    by_id.run(100, dt);
    renumbered.run(100, dt);
    merged.run(100, dt);
    bare.run(100, dt);
    CHECK(merged.waiting_pair_histories() == 0);
    REQUIRE(same_by_id(whole, by_id));
    REQUIRE(same_by_id(renumbered, merged));
    for (std::size_t i = 0; i < n; ++i) {
      REQUIRE(merged.particles().id[i] == renumbered.particles().id[i]);  // (same numbering)
      REQUIRE(merged.particles().force[i] == renumbered.particles().force[i]);
    }
  }
  CHECK(whole.wall_force(0) == by_id.wall_force(0));
  CHECK(whole.mesh_force(0) == by_id.mesh_force(0));
  CHECK(whole.neighbor_list().build_count() > builds);  // (the lists were built again meanwhile)
  // without the springs the bed steps on otherwise (numbered alike)
  CHECK_FALSE(same_by_id(whole, bare));
}

TEST_CASE("dem: a particle moved with its plane, mesh and breakage state keeps its records",
          "[dem][migration]") {
  // One sphere pressed into a side plane and onto a mesh floor (gravity tilted towards the
  // plane), sliding along the plane: springs with both, a breakage strength drawn.
  const auto setup = [](bool filled) {
    System sys;
    const int m = sys.add_material({1.0e7, 0.3, 2500.0});
    sys.add_interaction(m, m, {0.5, 0.5, 0.0});
    sys.set_gravity({-4.0, 0, -9.81});
    sys.set_skin(1e-4);
    sys.add_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), m);
    Eigen::MatrixX3d v(4, 3);
    v << -0.01, -0.01, 0, 0.01, -0.01, 0, 0.01, 0.01, 0, -0.01, 0.01, 0;
    TriangleMesh::Triangles t(2, 3);
    t << 0, 1, 2, 0, 2, 3;
    sys.add_mesh(v, t, m);
    BreakageParameters b;
    b.limit_strength = 1e12;  // (never reached: the strength is only carried)
    b.reference_size = 1e-3;
    b.weibull_modulus = 3.0;
    b.comminution_limit = 1e-4;
    sys.add_hook(std::make_unique<Breakage>(b));
    if (filled)
      sys.add_particle(Eigen::Vector3d(0.999e-3, -2e-3, 0.999e-3), 1e-3, m,
                       Eigen::Vector3d(0, 0.05, 0));
    return sys;
  };
  System origin = setup(true);
  const double dt = 0.2 * origin.rayleigh_time_step();
  origin.run(300, dt);
  REQUIRE(origin.mesh_contacts().contact_count() == 1);
  const auto plane_shear = [](const System& s) {
    return s.store().array<Eigen::Vector3d>(s.store().find("plane_shear"))[0];
  };
  const auto strength = [](const System& s) {
    return s.store().array<double>(s.store().find("breakage_strength"))[0];
  };
  REQUIRE(plane_shear(origin).norm() > 0.0);
  REQUIRE(strength(origin) > 0.0);
  const auto mesh_contact = [](const System& s) {
    std::pair<MeshContactRecord, Eigen::Vector3d> c;
    s.mesh_contacts().for_each_contact(
        [&](int, const MeshContactRecord& r, const Eigen::Vector3d& shear) {
          c = {r, shear};
        });
    return c;
  };
  REQUIRE(mesh_contact(origin).second.norm() > 0.0);

  // there and back again, through a system that holds other particles
  System there = setup(false), back = setup(false);
  const int m = 0;
  there.add_particle(Eigen::Vector3d(5e-3, 5e-3, 1e-3), 1e-3, m, Eigen::Vector3d::Zero(),
                     Eigen::Vector3d::Zero(), 100);
  // (a subdomain that steps: its forces are those of a pass, so the arriving particle's are used
  // as they came; a system that has not stepped computes every force at its first step)
  there.step(dt);
  std::vector<std::byte> message;
  origin.pack_particles({0}, message);
  const auto carried = [&](const System& s, std::size_t i) {
    CHECK(s.particles().id[i] == origin.particles().id[0]);
    CHECK(s.particles().force[i] == origin.particles().force[0]);  // (the last pass's)
    CHECK(s.store().array<Eigen::Vector3d>(s.store().find("plane_shear"))[i] ==
          plane_shear(origin));
    CHECK(s.store().array<double>(s.store().find("breakage_strength"))[i] == strength(origin));
    int contacts = 0;  // (of particle i)
    s.mesh_contacts().for_each_contact(
        [&](int k, const MeshContactRecord&, const Eigen::Vector3d&) { contacts += k == int(i); });
    CHECK(contacts == 1);
  };
  REQUIRE(there.unpack_particles(message.data(), message.size()) == 1);
  carried(there, 1);
  message.clear();
  there.pack_particles({1}, message);
  there.remove_particles({0, 1});
  REQUIRE(back.unpack_particles(message.data(), message.size()) == 0);
  carried(back, 0);
  const auto [r0, shear0] = mesh_contact(origin);
  const auto [r1, shear1] = mesh_contact(back);
  CHECK(std::memcmp(&r0, &r1, sizeof r0) == 0);
  CHECK(shear0 == shear1);

  origin.run(300, dt);
  back.run(300, dt);
  CHECK(same_by_id(origin, back));
  CHECK(origin.wall_force(0) == back.wall_force(0));
  CHECK(origin.mesh_force(0) == back.mesh_force(0));
  CHECK(there.particle_count() == 1);  // (the moved particle's mesh row left with it:)
  CHECK(there.mesh_contacts().row_count() == 1);
}

TEST_CASE("dem: malformed particle messages are refused with the system unchanged",
          "[dem][migration]") {
  System from = bed(true);
  const double dt = 0.2 * from.rayleigh_time_step();
  from.run(8000, dt);
  std::vector<int> which;
  for (std::size_t i = 0; i < from.particle_count(); i += 2) which.push_back(static_cast<int>(i));
  std::vector<std::byte> good;
  from.pack_particles(which, good);

  System to = bed(false);
  to.add_particle(Eigen::Vector3d(1e-3, 1e-3, 9e-3), 0.5e-3, 0, Eigen::Vector3d::Zero(),
                  Eigen::Vector3d::Zero(), 1000000);  // an id the message does not hold
  to.step(dt);  // (a system that has stepped: its plane histories are sized)
  const std::string before = state_bytes(to);
  const auto refused = [&](std::vector<std::byte> bytes, const char* what) {
    INFO(what);
    CHECK_THROWS_AS(to.unpack_particles(bytes.data(), bytes.size()), Error);
    CHECK(state_bytes(to) == before);
    CHECK(to.particle_count() == 1);
    CHECK(to.waiting_pair_histories() == 0);
  };
  const std::size_t header = 41, row = from.store().packed_bytes_per_particle();
  std::uint64_t records = 0;
  std::memcpy(&records, good.data() + 24, 8);
  REQUIRE(records > 0);
  const std::size_t pairs_at = header + which.size() * row;
  const std::size_t mesh_at = pairs_at + records * PairContacts::record_bytes;

  refused({good.begin(), good.end() - 1}, "cut short by a byte");
  refused({good.begin(), good.begin() + 20}, "shorter than the header");
  {
    auto b = good;
    b.push_back(std::byte{0});
    refused(b, "a byte too many");
  }
  {
    auto b = good;
    b[0] = std::byte{'X'};
    refused(b, "not a message");
  }
  {
    auto b = good;
    b[8] ^= std::byte{1};
    refused(b, "another layout");
  }
  {
    // the id array's first entry (found by its value, wherever the layout puts the array)
    // becomes the receiver's own particle's
    auto b = good;
    const std::int64_t dup = 1000000;
    const std::int64_t first_id = from.particles().id[which[0]];
    for (std::size_t at = header; at + 8 <= pairs_at; ++at) {
      std::int64_t v;
      std::memcpy(&v, b.data() + at, 8);
      if (v == first_id && at + 8 * which.size() <= pairs_at) {
        std::int64_t next;
        std::memcpy(&next, b.data() + at + 8, 8);
        if (next != from.particles().id[which[1]]) continue;
        std::memcpy(b.data() + at, &dup, 8);
        break;
      }
    }
    REQUIRE(std::memcmp(b.data(), good.data(), b.size()) != 0);
    refused(b, "an id the receiver holds");
  }
  {
    auto b = good;
    std::memcpy(b.data() + pairs_at + 8, b.data() + pairs_at, 8);  // id_j = id_i
    refused(b, "a pair of a particle with itself");
  }
  {
    auto b = good;
    const std::int32_t count = 99;
    std::memcpy(b.data() + mesh_at, &count, 4);
    refused(b, "too many mesh contacts");
  }
  // a message is taken once: the second time its ids are here already
  System once = bed(false);
  once.unpack_particles(good.data(), good.size());
  const std::size_t size = once.particle_count();
  CHECK_THROWS_AS(once.unpack_particles(good.data(), good.size()), Error);
  CHECK(once.particle_count() == size);
  // a receiver set up otherwise (one more plane: another width of the plane histories)
  System other = bed(false);
  other.add_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0);
  CHECK_THROWS_AS(other.unpack_particles(good.data(), good.size()), Error);
  CHECK(other.particle_count() == 0);
  // the sender refuses an index twice or one out of range
  std::vector<std::byte> out;
  CHECK_THROWS_AS(from.pack_particles({1, 1}, out), Error);
  CHECK_THROWS_AS(from.pack_particles({-1}, out), Error);
}
