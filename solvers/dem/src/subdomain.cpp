// A bed split into subdomains stepping to the same bits on any split (subdomain.hpp says why and
// how), and the in-process transport.
#include "partita/dem/subdomain.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <istream>
#include <ostream>
#include <sstream>
#include <string>

namespace partita::dem {

namespace {

constexpr std::uint32_t moves_magic = 0x4d445350u;    // "PSDM"
constexpr std::uint32_t refresh_magic = 0x52484750u;  // "PGHR"
constexpr std::uint32_t format_version = 2;  // 2: pair records carry the permanent overlap
constexpr std::size_t moves_header = 4 + 4 + 8 + 8;
constexpr std::size_t refresh_header = 4 + 4 + 8;
constexpr std::size_t refresh_row = 8 + 9 * 8;

template <class T>
void append(std::vector<std::byte>& out, const T& v) {
  const std::size_t at = out.size();
  out.resize(at + sizeof v);
  std::memcpy(out.data() + at, &v, sizeof v);
}
template <class T>
T get(const std::byte* at) {
  T v;
  std::memcpy(&v, at, sizeof v);
  return v;
}
void append_vector(std::vector<std::byte>& out, const Eigen::Vector3d& v) {
  for (int d = 0; d < 3; ++d) append(out, v[d]);
}
Eigen::Vector3d get_vector(const std::byte* at) {
  return {get<double>(at), get<double>(at + 8), get<double>(at + 16)};
}

std::string from(int rank, int source) {
  return "subdomain " + std::to_string(rank) + ": the message from subdomain " +
         std::to_string(source);
}

}  // namespace

// ---- InProcessTransport ---------------------------------------------------------------------

InProcessTransport::InProcessTransport(int parts) {
  if (parts < 1)
    throw Error("InProcessTransport: the number of subdomains must be >= 1, got " +
                std::to_string(parts));
  for (int r = 0; r < parts; ++r) local_.push_back(r);
}

void InProcessTransport::exchange(std::vector<SubdomainMail>& out, std::vector<SubdomainMail>& in) {
  const auto p = static_cast<std::size_t>(parts());
  if (out.size() != p) throw Error("InProcessTransport::exchange: need one outbox per subdomain");
  in.resize(p);
  for (std::size_t d = 0; d < p; ++d) {
    in[d].resize(p);
    if (out[d].size() != p)
      throw Error("InProcessTransport::exchange: need one buffer per subdomain in each outbox");
  }
  for (std::size_t s = 0; s < p; ++s)
    for (std::size_t d = 0; d < p; ++d) {
      in[d][s].swap(out[s][d]);
      out[s][d].clear();
    }
}

double InProcessTransport::max(const std::vector<double>& values) {
  double m = -std::numeric_limits<double>::infinity();
  for (const double v : values) m = std::max(m, v);
  return m;
}

// ---- MeshForceSums --------------------------------------------------------------------------

void MeshForceSums::reset(int vertices) {
  slot_.assign(static_cast<std::size_t>(vertices), -1);
  vertex_.clear();
  for (ExactSum& t : total_) t.clear();
}

ExactSum* MeshForceSums::vertex_sums(int vertex) {
  int& slot = slot_[static_cast<std::size_t>(vertex)];
  if (slot < 0) {
    slot = static_cast<int>(vertex_.size());
    vertex_.push_back(vertex);
    if (sums_.size() < 3 * vertex_.size()) sums_.resize(3 * vertex_.size());
    for (int c = 0; c < 3; ++c) sums_[3 * static_cast<std::size_t>(slot) + c].clear();
  }
  return sums_.data() + 3 * static_cast<std::size_t>(slot);
}

void MeshForceSums::add_vertex(int vertex, const Eigen::Vector3d& f) {
  ExactSum* s = vertex_sums(vertex);
  for (int c = 0; c < 3; ++c) s[c].add(f[c]);
}

void MeshForceSums::add_total(const Eigen::Vector3d& f) {
  for (int c = 0; c < 3; ++c) total_[c].add(f[c]);
}

// The sums in ExactSum's compact form (a vertex's force is a sum of a few terms of like size: a
// few of the 70 limbs in use, some 60 bytes a sum instead of 576).
void MeshForceSums::write(std::vector<std::byte>& out) const {
  std::size_t size = 8;
  for (const ExactSum& t : total_) size += t.compact_size();
  for (std::size_t k = 0; k < 3 * vertex_.size(); ++k) size += sums_[k].compact_size();
  size += 8 * vertex_.size();
  std::size_t at = out.size();
  out.resize(at + size);
  const std::uint64_t n = vertex_.size();
  std::memcpy(out.data() + at, &n, 8);
  at += 8;
  for (const ExactSum& t : total_) t.write_compact(out.data() + at), at += t.compact_size();
  for (std::size_t k = 0; k < vertex_.size(); ++k) {
    const std::int64_t v = vertex_[k];
    std::memcpy(out.data() + at, &v, 8);
    at += 8;
    for (int c = 0; c < 3; ++c) {
      const ExactSum& e = sums_[3 * k + c];
      e.write_compact(out.data() + at);
      at += e.compact_size();
    }
  }
}

void MeshForceSums::add_message(const std::vector<std::byte>& in, int source_rank) {
  const auto refuse = [&](const std::string& why) {
    throw Error("SubdomainStepper: the mesh forces of subdomain " + std::to_string(source_rank) +
                " " + why + " (the subdomains differ)");
  };
  const std::byte* at = in.data();
  const std::byte* const end = in.data() + in.size();
  ExactSum part;
  const auto read_sum = [&](ExactSum& into) {
    const std::size_t took = part.read_compact(at, static_cast<std::size_t>(end - at));
    if (took == 0) refuse("are cut short or not a mesh's force sums");
    into.add(part);
    at += took;
  };
  if (in.size() < 8) refuse("are cut short or not a mesh's force sums");
  const auto n = get<std::uint64_t>(at);
  at += 8;
  for (ExactSum& t : total_) read_sum(t);
  for (std::uint64_t k = 0; k < n; ++k) {
    if (end - at < 8) refuse("are cut short or not a mesh's force sums");
    const auto v = get<std::int64_t>(at);
    at += 8;
    if (v < 0 || static_cast<std::size_t>(v) >= slot_.size())
      refuse("name vertex " + std::to_string(v) + " of a mesh of " +
             std::to_string(slot_.size()) + " vertices");
    ExactSum* s = vertex_sums(static_cast<int>(v));
    for (int c = 0; c < 3; ++c) read_sum(s[c]);
  }
  if (at != end) refuse("have bytes after their last vertex");
}

void MeshForceSums::values(Eigen::MatrixX3d& vertex, Eigen::Vector3d& total) const {
  vertex.setZero(static_cast<Eigen::Index>(slot_.size()), 3);
  for (std::size_t k = 0; k < vertex_.size(); ++k)
    for (int c = 0; c < 3; ++c) vertex(vertex_[k], c) = sums_[3 * k + c].value();
  for (int c = 0; c < 3; ++c) total[c] = total_[c].value();
}

// ---- GlobalOrder ----------------------------------------------------------------------------

GlobalOrder::GlobalOrder(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double cell)
    : lo_(lo), cell_(cell) {
  if (!(cell > 0.0) || !std::isfinite(cell) || !lo.allFinite() || !hi.allFinite() ||
      !(lo.array() < hi.array()).all()) {
    std::ostringstream msg;
    msg << "GlobalOrder: need lo < hi (finite) and a cell size > 0, got lo " << lo.transpose()
        << ", hi " << hi.transpose() << ", cell " << cell;
    throw Error(msg.str());
  }
  for (int d = 0; d < 3; ++d)
    count_[d] = std::max<std::int64_t>(
        1, std::min<std::int64_t>(std::int64_t{1} << 20,
                                  static_cast<std::int64_t>(std::ceil((hi[d] - lo[d]) / cell))));
}

std::uint64_t GlobalOrder::cell(const Eigen::Vector3d& x) const {
  std::int64_t c[3];
  for (int d = 0; d < 3; ++d) {
    const double f = std::floor((x[d] - lo_[d]) / cell_);
    c[d] = f < 0.0 ? 0 : f >= static_cast<double>(count_[d]) ? count_[d] - 1
                                                              : static_cast<std::int64_t>(f);
  }
  return static_cast<std::uint64_t>((c[2] * count_[1] + c[1]) * count_[0] + c[0]);
}

bool GlobalOrder::compute(const Particles& p, std::vector<int>& order) {
  const std::size_t n = p.size();
  keys_.resize(n);
  for (std::size_t i = 0; i < n; ++i) keys_[i] = {{cell(p.position[i]), p.id[i]}, static_cast<int>(i)};
  std::sort(keys_.begin(), keys_.end());
  order.resize(n);
  bool identity = true;
  for (std::size_t k = 0; k < n; ++k) {
    order[k] = keys_[k].second;
    identity = identity && order[k] == static_cast<int>(k);
  }
  return !identity;
}

// ---- Subdomain ------------------------------------------------------------------------------

Subdomain::Subdomain(System& system, int rank, int parts) : sys_(&system), rank_(rank) {
  ParticleStore& store = sys_->store();
  h_owner_ = store.find("subdomain_owner");
  if (h_owner_ < 0) h_owner_ = store.add_array<int>("subdomain_owner", 1, -1);
  send_.resize(static_cast<std::size_t>(parts));
  recv_.resize(static_cast<std::size_t>(parts));
  migrants_.resize(static_cast<std::size_t>(parts));
  ghosts_.resize(static_cast<std::size_t>(parts));
}

std::size_t Subdomain::owned_count() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < sys_->particle_count(); ++i) n += is_ghost(i) ? 0 : 1;
  return n;
}

double Subdomain::max_radius() {
  double r = 0.0;
  for (const double ri : sys_->store_unsynced().core().radius) r = std::max(r, ri);
  return r;
}

// An empty subdomain moves its walls and meshes (phase_begin() without particles) and asks for
// no build: the others' lists decide, and its walls' and meshes' positions at its last build may
// be old.
void Subdomain::begin(double dt) { sys_->phase_begin(dt); }

double Subdomain::drift(double dt) {
  const double moved2 = sys_->phase_drift(dt, ghost_);
  if (sys_->particle_count() == 0) return 0.0;
  return sys_->phase_needs_rebuild(moved2) ? std::numeric_limits<double>::infinity() : moved2;
}

bool Subdomain::fusable(double dt, double& bound) const {
  bound = 0.0;
  if (sys_->particle_count() == 0) return true;
  if (drifted_.size() != sys_->particle_count()) return false;  // (a change since the build)
  return sys_->phase_fusable(dt, bound);
}

void Subdomain::drift_sent(double dt) { sys_->phase_drift_some(dt, sent_); }

void Subdomain::forces_fused(double dt) {
  if (sys_->particle_count() > 0) sys_->phase_forces_fused(dt, drifted_);
}

void Subdomain::pack_refresh(SubdomainMail& out) {
  const std::vector<std::int64_t>& id = sys_->store_unsynced().core().id;
  Eigen::Vector3d x, v, w;
  for (std::size_t r = 0; r < send_.size(); ++r) {
    std::vector<std::byte>& o = out[r];
    o.clear();
    if (send_[r].empty()) continue;
    append(o, refresh_magic);
    append(o, format_version);
    append(o, static_cast<std::uint64_t>(send_[r].size()));
    for (const int i : send_[r]) {
      sys_->phase_motion(static_cast<std::size_t>(i), x, v, w);
      append(o, id[i]);
      append_vector(o, x);
      append_vector(o, v);
      append_vector(o, w);
    }
  }
}

void Subdomain::unpack_refresh(const SubdomainMail& in) {
  const std::vector<std::int64_t>& id = sys_->store_unsynced().core().id;
  for (std::size_t s = 0; s < recv_.size(); ++s) {
    static const std::vector<std::byte> none;
    const std::vector<std::byte>& m = s < in.size() ? in[s] : none;
    const std::vector<int>& ghosts = recv_[s];
    if (m.empty() && ghosts.empty()) continue;
    const std::size_t n = ghosts.size();
    if (m.size() < refresh_header || get<std::uint32_t>(m.data()) != refresh_magic ||
        get<std::uint32_t>(m.data() + 4) != format_version ||
        get<std::uint64_t>(m.data() + 8) != n || m.size() != refresh_header + n * refresh_row)
      throw Error(from(rank_, static_cast<int>(s)) +
                  " is not the refresh of the " + std::to_string(n) +
                  " ghosts it owns here (another format version, or the subdomains disagree on "
                  "the ghosts since the last build)");
    const std::byte* at = m.data() + refresh_header;
    for (std::size_t k = 0; k < n; ++k, at += refresh_row) {
      const int i = ghosts[k];
      if (get<std::int64_t>(at) != id[i])
        throw Error(from(rank_, static_cast<int>(s)) + " names particle id " +
                    std::to_string(get<std::int64_t>(at)) + " where ghost " + std::to_string(k) +
                    " is id " + std::to_string(id[i]));
      sys_->set_phase_motion(static_cast<std::size_t>(i), get_vector(at + 8), get_vector(at + 32),
                             get_vector(at + 56));
    }
  }
}

void Subdomain::pack_moves(const DomainDecomposition& d, double ghost_distance,
                           SubdomainMail& out) {
  const std::size_t n = sys_->particle_count();
  const Particles& p = sys_->particles();  // (positions of now)
  for (auto& m : migrants_) m.clear();
  for (auto& g : ghosts_) g.clear();
  remove_.assign(n, 0);
  become_ghost_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (is_ghost(i)) {  // replaced by its owner's copy
      remove_[i] = 1;
      continue;
    }
    const Eigen::Vector3d& x = p.position[i];
    const int owner = d.owner(x);
    d.near(x, ghost_distance, near_);  // (boxes other than the owner's)
    bool ghost_here = false;
    for (const int r : near_) {
      if (r == rank_)
        ghost_here = true;
      else
        ghosts_[static_cast<std::size_t>(r)].push_back(static_cast<int>(i));
    }
    if (owner == rank_) continue;
    migrants_[static_cast<std::size_t>(owner)].push_back(static_cast<int>(i));
    if (ghost_here)
      become_ghost_.emplace_back(static_cast<int>(i), owner);
    else
      remove_[i] = 1;
  }
  for (std::size_t r = 0; r < out.size(); ++r) {
    std::vector<std::byte>& o = out[r];
    o.clear();
    if (migrants_[r].empty() && ghosts_[r].empty()) continue;
    append(o, moves_magic);
    append(o, format_version);
    append(o, std::uint64_t{0});
    append(o, std::uint64_t{0});
    std::size_t start = o.size();
    if (!migrants_[r].empty()) sys_->pack_particles(migrants_[r], o);
    const std::uint64_t migrant_bytes = o.size() - start;
    start = o.size();
    if (!ghosts_[r].empty()) sys_->pack_particles(ghosts_[r], o);
    const std::uint64_t ghost_bytes = o.size() - start;
    std::memcpy(o.data() + 8, &migrant_bytes, 8);
    std::memcpy(o.data() + 16, &ghost_bytes, 8);
  }
}

void Subdomain::unpack_moves(const SubdomainMail& in, GlobalOrder& order,
                             const DomainDecomposition& d, double ghost_distance) {
  // every message checked before the first change
  for (std::size_t s = 0; s < in.size(); ++s) {
    const std::vector<std::byte>& m = in[s];
    if (m.empty()) continue;
    if (m.size() < moves_header || get<std::uint32_t>(m.data()) != moves_magic ||
        get<std::uint32_t>(m.data() + 4) != format_version ||
        get<std::uint64_t>(m.data() + 8) + get<std::uint64_t>(m.data() + 16) !=
            m.size() - moves_header)
      throw Error(from(rank_, static_cast<int>(s)) +
                  " is not a message of particles moving at a list build (\"PSDM\", version " +
                  std::to_string(format_version) + ") or is cut short");
  }
  {
    std::vector<int>& owner = owner_array();
    for (const auto& [i, o] : become_ghost_) owner[static_cast<std::size_t>(i)] = o;
  }
  if (remove_.size() == sys_->particle_count()) sys_->remove_particles(remove_);
  remove_.clear();
  become_ghost_.clear();
  for (std::size_t s = 0; s < in.size(); ++s) {
    const std::vector<std::byte>& m = in[s];
    if (m.empty()) continue;
    const auto migrant_bytes = static_cast<std::size_t>(get<std::uint64_t>(m.data() + 8));
    const auto ghost_bytes = static_cast<std::size_t>(get<std::uint64_t>(m.data() + 16));
    const std::byte* at = m.data() + moves_header;
    if (migrant_bytes > 0) {
      const std::size_t first = sys_->unpack_particles(at, migrant_bytes);
      std::vector<int>& owner = owner_array();
      for (std::size_t i = first; i < owner.size(); ++i) owner[i] = -1;
      migrated_in_ += static_cast<long>(owner.size() - first);
    }
    if (ghost_bytes > 0) {
      // the owner is the box that holds it now, not the sender: a particle that leaves the
      // sender for another subdomain is sent here as a ghost by the sender, and refreshed by
      // its new owner until the next build
      const std::size_t first = sys_->unpack_particles(at + migrant_bytes, ghost_bytes);
      std::vector<int>& owner = owner_array();
      const std::vector<Eigen::Vector3d>& x = sys_->particles().position;
      for (std::size_t i = first; i < owner.size(); ++i) owner[i] = d.owner(x[i]);
    }
  }
  // the global order, the lists, and who sends what until the next build
  for (auto& l : send_) l.clear();
  for (auto& l : recv_) l.clear();
  ghost_.clear();
  sent_.clear();
  drifted_.clear();
  if (sys_->particle_count() == 0) return;
  if (order.compute(sys_->particles(), order_)) sys_->renumber_particles(order_);
  const std::vector<int>& owner = owner_array();
  const std::size_t n = sys_->particle_count();
  ghost_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) ghost_[i] = owner[i] >= 0 ? 1 : 0;
  // (a ghost's own force is not used: no pair of two ghosts, no plane or mesh contacts)
  sys_->phase_build(&ghost_);
  const Particles& p = sys_->particles();
  for (std::size_t i = 0; i < n; ++i) {
    if (owner[i] >= 0) {
      recv_[static_cast<std::size_t>(owner[i])].push_back(static_cast<int>(i));
      continue;
    }
    d.near(p.position[i], ghost_distance, near_);
    for (const int r : near_) send_[static_cast<std::size_t>(r)].push_back(static_cast<int>(i));
  }
  // the fused path's flags: ghosts take their values from their owners, and the owned particles
  // others read as ghosts take their first half before the refresh
  drifted_ = ghost_;
  for (const std::vector<int>& l : send_)
    for (const int i : l) drifted_[static_cast<std::size_t>(i)] = 1;
  for (std::size_t i = 0; i < n; ++i)
    if (drifted_[i] && !ghost_[i]) sent_.push_back(static_cast<int>(i));
}

void Subdomain::pack_owned(std::vector<std::byte>& out) {
  near_.clear();
  for (std::size_t i = 0; i < sys_->particle_count(); ++i)
    if (!is_ghost(i)) near_.push_back(static_cast<int>(i));
  sys_->pack_particles(near_, out);
}

void Subdomain::add_kinetic(ExactSum* sums) {
  const Particles& p = sys_->particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (is_ghost(i)) continue;
    sums[0].add(0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
               0.5 * p.inertia[i] * p.angular_velocity[i].squaredNorm());
    for (int k = 0; k < 3; ++k) sums[1 + k].add(p.mass[i] * p.velocity[i][k]);
  }
}

void Subdomain::set_changed() {
  sent_.clear();  // (until the next build: the exact path)
  drifted_.clear();
  const std::vector<int>& owner = owner_array();
  ghost_.assign(owner.size(), 0);
  for (std::size_t i = 0; i < owner.size(); ++i) ghost_[i] = owner[i] >= 0 ? 1 : 0;
}

void Subdomain::check_reactions() const {
  if (!sys_->planes().empty() && !sys_->wall_reactions_recorded())
    throw Error("subdomain " + std::to_string(rank_) +
                ": the planes' reactions are not recorded (System::set_wall_reactions(true) "
                "before the first force pass)");
}

void Subdomain::add_wall_forces(ExactSum* sums) const {
  check_reactions();
  const std::vector<PlaneWall>& planes = sys_->planes();
  for (std::size_t i = 0; i < sys_->particle_count(); ++i) {
    if (is_ghost(i)) continue;
    sys_->for_each_wall_reaction(i, [&](std::size_t k, const Eigen::Vector3d& f) {
      for (int c = 0; c < 3; ++c) sums[3 * planes[k].wall + c].add(f[c]);
    });
  }
}

void Subdomain::add_contacts(ExactSum& sum) const {
  const Particles& p = sys_->particles();
  double count = 0.0;  // (an integer: exact)
  sys_->neighbor_list().for_each_pair([&](int i, int j) {
    if (is_ghost(static_cast<std::size_t>(i))) return;
    const double rsum = p.radius[i] + p.radius[j];
    if ((p.position[i] - p.position[j]).squaredNorm() < rsum * rsum) count += 1.0;
  });
  sum.add(count);
}

void Subdomain::add_plane_forces(ExactSum* sums) const {
  check_reactions();
  for (std::size_t i = 0; i < sys_->particle_count(); ++i) {
    if (is_ghost(i)) continue;
    sys_->for_each_wall_reaction(i, [&](std::size_t k, const Eigen::Vector3d& f) {
      for (int c = 0; c < 3; ++c) sums[3 * k + c].add(f[c]);
    });
  }
}

void Subdomain::add_mesh_forces(int mesh, MeshForceSums& sums) const {
  if (sys_->particle_count() == 0) return;  // (rows of particles that left are gone)
  const TriangleMesh& m = sys_->mesh(mesh);
  sys_->mesh_contacts().for_each_contact(
      [&](int i, const MeshContactRecord& rec, const Eigen::Vector3d&) {
        if (rec.mesh != mesh || is_ghost(static_cast<std::size_t>(i))) return;
        const auto& tri = m.triangle(rec.triangle);
        // the terms MeshContacts::reduce() subtracts from the vertices' forces, exactly
        for (int k = 0; k < 3; ++k) sums.add_vertex(tri[k], -(rec.barycentric[k] * rec.force));
        sums.add_total(-rec.force);
      });
}

void Subdomain::add_step_energies(double dt, ExactSum* sums) const {
  const std::size_t n = sys_->particle_count();
  if (n == 0) return;
  const std::vector<System::ParticleEnergy>& e = sys_->particle_energies();
  const std::vector<PlaneWall>& planes = sys_->planes();
  if (e.size() != n || (!planes.empty() && !sys_->wall_reactions_recorded()))
    throw Error("subdomain " + std::to_string(rank_) +
                ": the particles' energies or the planes' reactions are not recorded "
                "(System::set_energy_terms(true) and set_wall_reactions(true) before the step)");
  for (std::size_t i = 0; i < n; ++i) {
    if (is_ghost(i)) continue;
    sums[0].add(e[i].damping);
    sums[1].add(e[i].friction);
    sums[2].add(e[i].gravity);
    sums[3].add(e[i].stiffening);
    sys_->for_each_wall_reaction(i, [&](std::size_t k, const Eigen::Vector3d& f) {
      if (planes[k].velocity != Eigen::Vector3d::Zero())
        sums[4 + planes[k].wall].add(-f.dot(planes[k].velocity) * dt);
    });
  }
  const std::size_t walls = static_cast<std::size_t>(sys_->wall_count());
  sys_->mesh_contacts().for_each_contact(
      [&](int i, const MeshContactRecord& rec, const Eigen::Vector3d&) {
        if (is_ghost(static_cast<std::size_t>(i))) return;
        const Eigen::Vector3d v_wall =
            sys_->mesh(rec.mesh).velocity_at(rec.triangle, rec.barycentric);
        sums[4 + walls + static_cast<std::size_t>(rec.mesh)].add(rec.force.dot(v_wall) * dt);
      });
}

void Subdomain::forces(double dt, bool step) {
  if (sys_->particle_count() > 0) sys_->phase_forces(dt, step);
}

void Subdomain::finish(double dt, double moved) { sys_->phase_finish(dt, moved); }

// ---- SubdomainStepper -----------------------------------------------------------------------

SubdomainStepper::SubdomainStepper(std::vector<System*> systems, SubdomainTransport& transport,
                                   const DomainDecomposition& decomposition, double skin,
                                   Options options)
    : transport_(&transport),
      decomposition_(decomposition),
      skin_(skin),
      options_(options) {
  const std::vector<int>& local = transport.local();
  if (systems.size() != local.size() || decomposition.parts() != transport.parts()) {
    std::ostringstream msg;
    msg << "SubdomainStepper: " << systems.size() << " systems for the " << local.size()
        << " local subdomains of the transport, which has " << transport.parts()
        << " subdomains in all, and a decomposition into " << decomposition.parts()
        << "; give one System per local subdomain and a decomposition into as many boxes as "
           "subdomains";
    throw Error(msg.str());
  }
  const int parts = transport.parts();
  for (std::size_t k = 0; k < systems.size(); ++k) {
    if (systems[k] == nullptr) throw Error("SubdomainStepper: system " + std::to_string(k) + " is null");
    systems[k]->set_skin(skin);
    systems[k]->set_sort_interval(0);
    systems[k]->set_wall_reactions(true);
    systems[k]->set_local_fragment_insertion(false);  // (the split builds its lists again)
    subdomains_.emplace_back(*systems[k], local[k], parts);
  }
  for (int h = 0; h < systems[0]->hook_count(); ++h)
    if (systems[0]->hook(h).replaces_particles()) replacing_.push_back(h);
  replaced_.resize(systems.size());
  removed_.resize(systems.size());
  first_id_.resize(systems.size());
  out_.assign(systems.size(), SubdomainMail(static_cast<std::size_t>(parts)));
  in_.assign(systems.size(), SubdomainMail(static_cast<std::size_t>(parts)));
  values_.assign(systems.size(), 0.0);
}

void SubdomainStepper::set_decomposition(const DomainDecomposition& d) {
  if (d.parts() != decomposition_.parts() || d.bounds().lo != decomposition_.bounds().lo ||
      d.bounds().hi != decomposition_.bounds().hi)
    throw Error(
        "SubdomainStepper::set_decomposition: a new decomposition must have as many boxes and "
        "the same bounds as the first (the global order's grid is fixed for the run)");
  next_ = d;
  next_pending_ = true;
}

void SubdomainStepper::redistribute() {
  motion_known_ = false;  // (a build: the next motion bound comes from a pass with a kick)
  for (std::size_t k = 0; k < subdomains_.size(); ++k) values_[k] = subdomains_[k].max_radius();
  const double r_max = transport_->max(values_);
  if (!(r_max > 0.0))
    throw Error("SubdomainStepper: the split bed has no particles; add some first");
  ghost_distance_ = options_.ghost_distance >= 0.0 ? options_.ghost_distance : 2.0 * r_max + skin_;
  if (!started_) {
    const DomainDecomposition::Box& b = decomposition_.bounds();
    order_ = GlobalOrder(b.lo, b.hi, 2.0 * r_max + skin_);
  }
  if (next_pending_) {
    decomposition_ = next_;
    next_pending_ = false;
  }
  for (std::size_t k = 0; k < subdomains_.size(); ++k)
    subdomains_[k].pack_moves(decomposition_, ghost_distance_, out_[k]);
  transport_->exchange(out_, in_);
  for (std::size_t k = 0; k < subdomains_.size(); ++k)
    subdomains_[k].unpack_moves(in_[k], order_, decomposition_, ghost_distance_);
  ++builds_;
}

void SubdomainStepper::start(double dt) {
  redistribute();
  started_ = true;
  for (Subdomain& s : subdomains_) s.forces(dt, false);
  update_rayleigh();
}

void SubdomainStepper::update_rayleigh() {
  for (std::size_t k = 0; k < subdomains_.size(); ++k) {
    const System& sys = subdomains_[k].system();
    values_[k] = sys.particle_count() > 0 ? -sys.rayleigh_time_step()
                                          : -std::numeric_limits<double>::max();
  }
  rayleigh_ = -transport_->max(values_);
}

void SubdomainStepper::resume() {
  if (started_)
    throw Error("SubdomainStepper::resume: the stepper has started already; resume() replaces "
                "start() for the particles of a restart");
  redistribute();
  started_ = true;
  update_rayleigh();
}

void SubdomainStepper::set_energy_accounting(bool on) {
  if (started_)
    throw Error("SubdomainStepper::set_energy_accounting: turn it on or off before start() or "
                "resume()");
  energy_ = on;
  for (Subdomain& sd : subdomains_) sd.system().set_energy_terms(on);
}

std::size_t SubdomainStepper::book_count() const {
  const System& sys = subdomains_[0].system();
  // damping, friction, gravity, stiffening, the walls', the meshes', breakage
  return 5 + static_cast<std::size_t>(sys.wall_count()) + static_cast<std::size_t>(sys.mesh_count());
}

double SubdomainStepper::half_step_term(double dt) {
  sum_dt_ = dt;
  global_sums(Sums::half_step);
  return totals_[0].value();
}

void SubdomainStepper::step(double dt) {
  if (!started_) start(dt);
  if (energy_) {  // the books' start (collective: every process steps alike)
    if (books_.size() != subdomains_.size())
      books_.assign(subdomains_.size(), std::vector<ExactSum>(book_count()));
    if (!books_started_) {
      books_started_ = true;
      books_dt_ = dt;
      kinetic_start_ = kinetic_energy() + half_step_term(dt);
      elastic_start_ = elastic_energy();
    } else if (dt != books_dt_) {  // the half-step term of the state now, at the new step
      kinetic_start_ += half_step_term(dt) - half_step_term(books_dt_);
      books_dt_ = dt;
    }
  }
  for (Subdomain& s : subdomains_) s.begin(dt);
  // The fused path where every subdomain's motion bound rules out a build (one max), as
  // System::step() takes it: the particles others read as ghosts take their first half, their
  // values go out, then each pass takes the other particles' first half inside it. Else the
  // exact path: every first half, the rebuild decision over the split (the largest displacement
  // since the build, +infinity where a subdomain needs a build), the ghosts' values or a build.
  bool fused = false;
  if (motion_known_ && options_.fused) {
    bounds_.resize(subdomains_.size());
    for (std::size_t k = 0; k < subdomains_.size(); ++k)
      values_[k] = subdomains_[k].fusable(dt, bounds_[k]) ? 0.0 : 1.0;
    fused = !(transport_->max(values_) > 0.0);
  }
  double moved = 0.0;  // (the exact path: over the split, from the build positions)
  if (fused) {
    for (Subdomain& s : subdomains_) s.drift_sent(dt);
    refresh();
    for (Subdomain& s : subdomains_) s.forces_fused(dt);
    ++fused_steps_;
  } else {
    for (std::size_t k = 0; k < subdomains_.size(); ++k) values_[k] = subdomains_[k].drift(dt);
    const double moved2 = transport_->max(values_);
    const bool rebuild = !(moved2 < std::numeric_limits<double>::infinity());
    if (rebuild)
      redistribute();
    else
      refresh();
    moved = rebuild ? 0.0 : std::sqrt(moved2);
    for (Subdomain& s : subdomains_) s.forces(dt, true);
  }
  if (energy_)
    for (std::size_t k = 0; k < subdomains_.size(); ++k)
      subdomains_[k].add_step_energies(dt, books_[k].data());
  for (std::size_t k = 0; k < subdomains_.size(); ++k)
    subdomains_[k].finish(dt, fused ? bounds_[k] : moved);
  motion_known_ = true;
  ++steps_;
  if (!replacing_.empty()) replace_particles(dt);
}

void SubdomainStepper::refresh() {
  for (std::size_t k = 0; k < subdomains_.size(); ++k) subdomains_[k].pack_refresh(out_[k]);
  transport_->exchange(out_, in_);
  for (std::size_t k = 0; k < subdomains_.size(); ++k) subdomains_[k].unpack_refresh(in_[k]);
}

double SubdomainStepper::mechanical_energy(double dt) {
  return kinetic_energy() + half_step_term(dt) + elastic_energy();
}

void SubdomainStepper::replace_particles(double dt) {
  for (const int h : replacing_) {
    // what each subdomain replaces among the particles it owns, and whether any does
    for (std::size_t k = 0; k < subdomains_.size(); ++k) {
      Subdomain& sd = subdomains_[k];
      replaced_[k].clear();
      removed_[k].clear();
      if (sd.system().particle_count() > 0)
        sd.system().hook(h).choose(sd.system(), sd.ghost_flags(), replaced_[k], removed_[k]);
      values_[k] = static_cast<double>(replaced_[k].size() + removed_[k].size());
    }
    if (!(transport_->max(values_) > 0.0)) continue;
    // the replaced particles' ids to every subdomain: the new ids follow their order
    for (std::size_t k = 0; k < subdomains_.size(); ++k) {
      const std::vector<std::int64_t>& id = subdomains_[k].system().particles().id;
      for (std::vector<std::byte>& o : out_[k]) {
        o.resize(replaced_[k].size() * sizeof(std::int64_t));
        std::byte* at = o.data();
        for (const std::size_t i : replaced_[k]) {
          std::memcpy(at, &id[i], sizeof(std::int64_t));
          at += sizeof(std::int64_t);
        }
      }
    }
    transport_->exchange(out_, in_);
    all_ids_.clear();
    for (const std::vector<std::byte>& m : in_[0])
      for (std::size_t at = 0; at + sizeof(std::int64_t) <= m.size(); at += sizeof(std::int64_t)) {
        std::int64_t v;
        std::memcpy(&v, m.data() + at, sizeof v);
        all_ids_.push_back(v);
      }
    std::sort(all_ids_.begin(), all_ids_.end());
    for (std::size_t k = 0; k < subdomains_.size(); ++k)
      values_[k] = static_cast<double>(subdomains_[k].system().store().next_id());
    const auto next = static_cast<std::int64_t>(transport_->max(values_));
    const std::int64_t successors = subdomains_[0].system().hook(h).successors();
    const double before = energy_ && books_started_ ? mechanical_energy(dt) : 0.0;
    for (std::size_t k = 0; k < subdomains_.size(); ++k) {
      Subdomain& sd = subdomains_[k];
      if (replaced_[k].empty() && removed_[k].empty()) continue;
      const std::vector<std::int64_t>& id = sd.system().particles().id;
      first_id_[k].clear();
      for (const std::size_t i : replaced_[k]) {
        const auto rank = std::lower_bound(all_ids_.begin(), all_ids_.end(), id[i]) - all_ids_.begin();
        first_id_[k].push_back(next + successors * static_cast<std::int64_t>(rank));
      }
      sd.system().hook(h).replace(sd.system(), replaced_[k], removed_[k], first_id_[k]);
      sd.set_changed();
    }
    const std::int64_t next_after = next + successors * static_cast<std::int64_t>(all_ids_.size());
    for (Subdomain& sd : subdomains_) sd.system().store().reserve_ids(next_after);
    // the new set's ghosts, lists and forces (a particle's force and contacts from this pass)
    redistribute();
    for (Subdomain& sd : subdomains_) sd.forces(dt, false);
    for (Subdomain& sd : subdomains_)
      if (sd.system().particle_count() > 0)
        sd.system().hook(h).settled(sd.system(), sd.ghost_flags(), next, next_after);
    if (energy_ && books_started_) {
      const double after = mechanical_energy(dt);
      const std::vector<int>& local = transport_->local();
      const auto first = std::find(local.begin(), local.end(), 0);
      if (first != local.end())  // (booked once: on subdomain 0)
        books_[static_cast<std::size_t>(first - local.begin())][breakage_book()].add(before - after);
    }
    update_rayleigh();
    ++replacement_steps_;
  }
}

std::pair<std::size_t, double> SubdomainStepper::particle_totals() {
  global_sums(Sums::totals);
  return {static_cast<std::size_t>(totals_[0].value()), totals_[1].value()};
}

std::vector<double> SubdomainStepper::hook_sums(int hook) {
  sum_hook_ = hook;
  global_sums(Sums::hook);
  std::vector<double> v(totals_.size());
  for (std::size_t q = 0; q < v.size(); ++q) v[q] = totals_[q].value();
  return v;
}

std::vector<std::vector<ExactSum>> SubdomainStepper::hook_totals() {
  const System& sys = subdomains_[0].system();
  std::vector<std::vector<ExactSum>> t(static_cast<std::size_t>(sys.hook_count()));
  for (int h = 0; h < sys.hook_count(); ++h) {
    if (sys.hook(h).sums().empty()) continue;
    sum_hook_ = h;
    global_sums(Sums::hook);
    t[static_cast<std::size_t>(h)] = totals_;
  }
  return t;
}

System::Energies SubdomainStepper::energies() {
  System::Energies e;
  if (!energy_ || !books_started_) return e;
  global_sums(Sums::books);
  e.started = true;
  e.damping = totals_[0].value();
  e.friction = totals_[1].value();
  e.gravity = totals_[2].value();
  e.stiffening = totals_[3].value();
  const System& sys = subdomains_[0].system();
  const auto walls = static_cast<std::size_t>(sys.wall_count());
  e.wall_work.resize(walls);
  for (std::size_t w = 0; w < walls; ++w) e.wall_work[w] = totals_[4 + w].value();
  e.mesh_work.resize(static_cast<std::size_t>(sys.mesh_count()));
  for (std::size_t m = 0; m < e.mesh_work.size(); ++m) e.mesh_work[m] = totals_[4 + walls + m].value();
  e.breakage = totals_[breakage_book()].value();
  e.kinetic_start = kinetic_start_;
  e.elastic_start = elastic_start_;
  return e;
}

double SubdomainStepper::energy_balance_error() {
  const System::Energies e = energies();
  if (!e.started) return 0.0;
  return System::balance_error(e, kinetic_energy() + half_step_term(books_dt_), elastic_energy());
}

// books(): "PSBK" (u32), started (u8), kinetic_start, elastic_start, the step (3 f64), the count
// of sums (u64), the sums (ExactSum::write(), each over every subdomain)
namespace {
constexpr std::uint32_t books_magic = 0x4b425350u;  // "PSBK"
constexpr std::size_t books_head = 4 + 1 + 3 * 8 + 8;
}  // namespace

std::vector<std::byte> SubdomainStepper::books() {
  std::vector<std::byte> out;
  if (!energy_) return out;
  const std::size_t m = book_count();
  if (books_.size() != subdomains_.size())
    books_.assign(subdomains_.size(), std::vector<ExactSum>(m));
  global_sums(Sums::books);
  out.resize(books_head + m * ExactSum::byte_size);
  std::byte* at = out.data();
  const auto put = [&](const auto& v) {
    std::memcpy(at, &v, sizeof v);
    at += sizeof v;
  };
  put(books_magic);
  put(static_cast<std::uint8_t>(books_started_ ? 1 : 0));
  put(kinetic_start_);
  put(elastic_start_);
  put(books_dt_);
  put(static_cast<std::uint64_t>(m));
  for (std::size_t q = 0; q < m; ++q, at += ExactSum::byte_size) totals_[q].write(at);
  return out;
}

void SubdomainStepper::restore_books(const std::vector<std::byte>& bytes) {
  if (!energy_)
    throw Error("SubdomainStepper::restore_books: the energy accounting is off "
                "(set_energy_accounting(true) before resume())");
  const std::size_t m = book_count();
  std::uint32_t magic = 0;
  std::uint64_t count = 0;
  if (bytes.size() >= books_head) {
    std::memcpy(&magic, bytes.data(), 4);
    std::memcpy(&count, bytes.data() + books_head - 8, 8);
  }
  // (books written before the breakage's book have one sum less: no breakage booked)
  if (magic != books_magic || (count != m && count + 1 != m) ||
      bytes.size() != books_head + count * ExactSum::byte_size)
    throw Error("SubdomainStepper::restore_books: the restart's energy books do not fit this "
                "split (" + std::to_string(count) + " sums for " + std::to_string(m) +
                " = 5 + walls + meshes, or not books at all)");
  books_started_ = std::to_integer<std::uint8_t>(bytes[4]) != 0;
  std::memcpy(&kinetic_start_, bytes.data() + 5, 8);
  std::memcpy(&elastic_start_, bytes.data() + 13, 8);
  std::memcpy(&books_dt_, bytes.data() + 21, 8);
  books_.assign(subdomains_.size(), std::vector<ExactSum>(m));
  // the sums over every subdomain go to subdomain 0's (exact: where they are added up does not
  // matter), on its process only
  const std::vector<int>& local = transport_->local();
  const auto first = std::find(local.begin(), local.end(), 0);
  if (first == local.end()) return;
  std::vector<ExactSum>& b = books_[static_cast<std::size_t>(first - local.begin())];
  for (std::size_t q = 0; q < count; ++q)
    b[q].read(bytes.data() + books_head + q * ExactSum::byte_size);
}

// Every subdomain sends its partial sums to every subdomain (itself included); each adds them up
// (exact: in any order).
void SubdomainStepper::global_sums(Sums what) {
  const std::size_t local = subdomains_.size();
  const auto walls = static_cast<std::size_t>(subdomains_[0].system().wall_count());
  const std::size_t planes = subdomains_[0].system().planes().size();
  const std::size_t m = what == Sums::kinetic ? 4
                        : what == Sums::elastic || what == Sums::contacts ||
                                  what == Sums::half_step
                            ? 1
                        : what == Sums::totals ? 2
                        : what == Sums::hook
                            ? subdomains_[0].system().hook(sum_hook_).sums().size()
                        : what == Sums::walls ? 3 * walls
                        : what == Sums::books ? book_count()
                                              : 3 * planes;
  sums_.resize(m * local);
  totals_.resize(m);
  for (std::size_t k = 0; k < local; ++k) {
    ExactSum* sums = sums_.data() + m * k;
    for (std::size_t q = 0; q < m; ++q) sums[q].clear();
    const Subdomain& sd = subdomains_[k];
    if (what == Sums::books)  // (cumulative, also where the subdomain is empty now)
      for (std::size_t q = 0; q < m; ++q) sums[q] = books_[k][q];
    else if (what == Sums::hook) {  // (the same)
      const std::vector<ExactSum> h = sd.system().hook(sum_hook_).sums();
      for (std::size_t q = 0; q < m && q < h.size(); ++q) sums[q] = h[q];
    }
    else if (sd.system().particle_count() == 0)
      ;  // (nothing to add)
    else if (what == Sums::half_step)
      sd.add_half_step(sum_dt_, sums[0]);
    else if (what == Sums::totals) {
      sums[0].add(static_cast<double>(sd.owned_count()));
      const Particles& p = sd.system().particles();
      for (std::size_t i = 0; i < p.size(); ++i)
        if (!sd.is_ghost(i)) sums[1].add(p.mass[i]);
    }
    else if (what == Sums::kinetic)
      subdomains_[k].add_kinetic(sums);
    else if (what == Sums::elastic)
      sd.add_elastic(sums[0]);
    else if (what == Sums::contacts)
      sd.add_contacts(sums[0]);
    else if (what == Sums::walls)
      sd.add_wall_forces(sums);
    else
      sd.add_plane_forces(sums);
    for (std::vector<std::byte>& o : out_[k]) {
      o.resize(m * ExactSum::byte_size);
      for (std::size_t q = 0; q < m; ++q) sums[q].write(o.data() + q * ExactSum::byte_size);
    }
  }
  transport_->exchange(out_, in_);
  for (ExactSum& t : totals_) t.clear();
  ExactSum part;
  for (const std::vector<std::byte>& msg : in_[0]) {
    if (msg.size() != m * ExactSum::byte_size)
      throw Error("SubdomainStepper: a subdomain's partial sums have " +
                  std::to_string(msg.size()) + " bytes, not " +
                  std::to_string(m * ExactSum::byte_size) + " (the subdomains differ)");
    for (std::size_t q = 0; q < m; ++q) {
      part.read(msg.data() + q * ExactSum::byte_size);
      totals_[q].add(part);
    }
  }
}

double SubdomainStepper::kinetic_energy() {
  global_sums(Sums::kinetic);
  return totals_[0].value();
}

double SubdomainStepper::elastic_energy() {
  global_sums(Sums::elastic);
  return totals_[0].value();
}

std::size_t SubdomainStepper::contact_count() {
  global_sums(Sums::contacts);
  return static_cast<std::size_t>(totals_[0].value());
}

Eigen::Vector3d SubdomainStepper::wall_force(int wall) {
  if (wall < 0 || wall >= subdomains_[0].system().wall_count())
    throw Error("SubdomainStepper::wall_force: no wall " + std::to_string(wall) + "; there are " +
                std::to_string(subdomains_[0].system().wall_count()));
  global_sums(Sums::walls);
  const std::size_t w = 3 * static_cast<std::size_t>(wall);
  return {totals_[w].value(), totals_[w + 1].value(), totals_[w + 2].value()};
}

const std::vector<Eigen::Vector3d>& SubdomainStepper::wall_forces() {
  global_sums(Sums::walls);
  forces_.resize(totals_.size() / 3);
  for (std::size_t w = 0; w < forces_.size(); ++w)
    forces_[w] = {totals_[3 * w].value(), totals_[3 * w + 1].value(), totals_[3 * w + 2].value()};
  return forces_;
}

const std::vector<Eigen::Vector3d>& SubdomainStepper::plane_forces() {
  global_sums(Sums::planes);
  forces_.resize(totals_.size() / 3);
  for (std::size_t k = 0; k < forces_.size(); ++k)
    forces_[k] = {totals_[3 * k].value(), totals_[3 * k + 1].value(), totals_[3 * k + 2].value()};
  return forces_;
}

Eigen::Vector3d SubdomainStepper::linear_momentum() {
  global_sums(Sums::kinetic);
  return {totals_[1].value(), totals_[2].value(), totals_[3].value()};
}

// Each local subdomain's owned contacts into its sums, sent to every subdomain; each adds them
// up (exact: in any order) and rounds; then the triangles' shares as MeshContacts::reduce()
// takes them (the same operations on the same vertex forces).
void SubdomainStepper::mesh_sums(int mesh) {
  const System& first = subdomains_[0].system();
  if (mesh < 0 || mesh >= first.mesh_count())
    throw Error("SubdomainStepper: no mesh " + std::to_string(mesh) + "; there are " +
                std::to_string(first.mesh_count()));
  const TriangleMesh& m = first.mesh(mesh);
  const int nv = m.vertex_count();
  mesh_parts_.resize(subdomains_.size());
  for (std::size_t k = 0; k < subdomains_.size(); ++k) {
    if (subdomains_[k].system().mesh_count() != first.mesh_count() ||
        subdomains_[k].system().mesh(mesh).vertex_count() != nv)
      throw Error("SubdomainStepper: the subdomains' meshes differ (every subdomain holds every "
                  "mesh, set up alike)");
    MeshForceSums& part = mesh_parts_[k];
    part.reset(nv);
    subdomains_[k].add_mesh_forces(mesh, part);
    out_[k][0].clear();
    part.write(out_[k][0]);
    for (std::size_t d = 1; d < out_[k].size(); ++d) out_[k][d] = out_[k][0];
  }
  transport_->exchange(out_, in_);
  mesh_all_.reset(nv);
  for (std::size_t s = 0; s < in_[0].size(); ++s)
    mesh_all_.add_message(in_[0][s], static_cast<int>(s));
  mesh_all_.values(mesh_vertex_, mesh_total_);
  // each vertex's share: 1 / (its active triangles), as TriangleMesh keeps it
  mesh_share_.assign(static_cast<std::size_t>(nv), 0.0);
  for (int t = 0; t < m.triangle_count(); ++t)
    if (m.triangle_active(t))
      for (const int v : m.triangle(t)) mesh_share_[static_cast<std::size_t>(v)] += 1.0;
  for (double& share : mesh_share_) share = share > 0.0 ? 1.0 / share : 0.0;
  mesh_triangle_.setZero(m.triangle_count(), 3);
  for (int t = 0; t < m.triangle_count(); ++t) {
    if (!m.triangle_active(t)) continue;
    const auto& tri = m.triangle(t);
    mesh_triangle_.row(t) = mesh_share_[tri[0]] * mesh_vertex_.row(tri[0]) +
                            mesh_share_[tri[1]] * mesh_vertex_.row(tri[1]) +
                            mesh_share_[tri[2]] * mesh_vertex_.row(tri[2]);
  }
}

const Eigen::MatrixX3d& SubdomainStepper::triangle_forces(int mesh) {
  mesh_sums(mesh);
  return mesh_triangle_;
}

const Eigen::MatrixX3d& SubdomainStepper::vertex_forces(int mesh) {
  mesh_sums(mesh);
  return mesh_vertex_;
}

Eigen::Vector3d SubdomainStepper::mesh_force(int mesh) {
  mesh_sums(mesh);
  return mesh_total_;
}

void SubdomainStepper::run(long steps, double dt) {
  for (long s = 0; s < steps; ++s) step(dt);
}

// ---- SplitRestart ---------------------------------------------------------------------------

namespace {
constexpr std::uint32_t restart_magic = 0x53525350u;  // "PSRS"
// (1: without the energy books, 2: without the hooks' sums; both still read)
constexpr std::uint32_t restart_version = 3;

template <class T>
void put_value(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T get_value(std::istream& in, const char* what) {
  T v;
  if (!in.read(reinterpret_cast<char*>(&v), sizeof v))
    throw Error(std::string("SplitRestart::read: the stream ends before ") + what);
  return v;
}
void get_bytes(std::istream& in, char* to, std::size_t n, const char* what) {
  if (!in.read(to, static_cast<std::streamsize>(n)))
    throw Error(std::string("SplitRestart::read: the stream ends inside ") + what);
}
}  // namespace

// Each local subdomain sends its owned particles to subdomain 0 (an exchange with one non-empty
// buffer a subdomain); subdomain 0's process receives every part, in the order of the ranks.
SplitRestart SplitRestart::gather(SubdomainStepper& stepper) {
  SubdomainTransport& transport = stepper.transport();
  const auto local = static_cast<std::size_t>(stepper.local_count());
  std::vector<SubdomainMail> out(local, SubdomainMail(static_cast<std::size_t>(transport.parts())));
  std::vector<SubdomainMail> in;
  std::vector<std::byte> books = stepper.books();  // (collective)
  std::vector<std::vector<ExactSum>> hooks = stepper.hook_totals();  // (the same)
  for (std::size_t k = 0; k < local; ++k)
    if (stepper.subdomain(static_cast<int>(k)).owned_count() > 0)
      stepper.subdomain(static_cast<int>(k)).pack_owned(out[k][0]);
  transport.exchange(out, in);
  SplitRestart r;
  if (transport.local()[0] != 0) return r;  // (held by subdomain 0's process)
  r.books_ = std::move(books);
  r.hooks_ = std::move(hooks);
  std::ostringstream world(std::ios::binary);
  stepper.subdomain(0).system().write_state(world);
  r.world_ = std::move(world).str();
  r.owned_ = std::move(in[0]);
  return r;
}

void SplitRestart::write(std::ostream& out) const {
  if (!holds())
    throw Error("SplitRestart::write: this process holds no restart (a split bed's restart is "
                "gathered on the process of subdomain 0: write it there)");
  put_value(out, restart_magic);
  put_value(out, restart_version);
  put_value(out, static_cast<std::uint64_t>(world_.size()));
  out.write(world_.data(), static_cast<std::streamsize>(world_.size()));
  put_value(out, static_cast<std::uint64_t>(owned_.size()));
  for (const std::vector<std::byte>& m : owned_) {
    put_value(out, static_cast<std::uint64_t>(m.size()));
    out.write(reinterpret_cast<const char*>(m.data()), static_cast<std::streamsize>(m.size()));
  }
  put_value(out, static_cast<std::uint64_t>(books_.size()));
  out.write(reinterpret_cast<const char*>(books_.data()), static_cast<std::streamsize>(books_.size()));
  put_value(out, static_cast<std::uint64_t>(hooks_.size()));
  std::vector<std::byte> b(ExactSum::byte_size);
  for (const std::vector<ExactSum>& h : hooks_) {
    put_value(out, static_cast<std::uint64_t>(h.size()));
    for (const ExactSum& x : h) {
      x.write(b.data());
      out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    }
  }
}

SplitRestart SplitRestart::read(std::istream& in) {
  if (get_value<std::uint32_t>(in, "its magic") != restart_magic)
    throw Error("SplitRestart::read: not a split bed's restart (no \"PSRS\" at the start)");
  const auto version = get_value<std::uint32_t>(in, "its version");
  if (version < 1 || version > restart_version)
    throw Error("SplitRestart::read: format version " + std::to_string(version) +
                "; this build reads 1 to " + std::to_string(restart_version));
  SplitRestart r;
  r.world_.resize(get_value<std::uint64_t>(in, "the world's size"));
  get_bytes(in, r.world_.data(), r.world_.size(), "the world's state");
  r.owned_.resize(get_value<std::uint64_t>(in, "the number of parts"));
  for (std::vector<std::byte>& m : r.owned_) {
    m.resize(get_value<std::uint64_t>(in, "a part's size"));
    get_bytes(in, reinterpret_cast<char*>(m.data()), m.size(), "a part's particles");
  }
  if (version >= 2) {
    r.books_.resize(get_value<std::uint64_t>(in, "the energy books' size"));
    get_bytes(in, reinterpret_cast<char*>(r.books_.data()), r.books_.size(), "the energy books");
  }
  if (version >= 3) {
    r.hooks_.resize(get_value<std::uint64_t>(in, "the number of hooks"));
    std::vector<std::byte> b(ExactSum::byte_size);
    for (std::vector<ExactSum>& h : r.hooks_) {
      const auto n = get_value<std::uint64_t>(in, "a hook's number of sums");
      if (n > 4096) throw Error("SplitRestart::read: a hook with " + std::to_string(n) + " sums");
      h.resize(n);
      for (ExactSum& x : h) {
        get_bytes(in, reinterpret_cast<char*>(b.data()), b.size(), "a hook's sums");
        x.read(b.data());
      }
    }
  }
  return r;
}

void SplitRestart::restore(const std::vector<System*>& systems) const { restore(systems, 0); }

void SplitRestart::restore(const std::vector<System*>& systems,
                           const SubdomainTransport& transport) const {
  if (systems.size() != transport.local().size())
    throw Error("SplitRestart::restore: " + std::to_string(systems.size()) +
                " systems for the " + std::to_string(transport.local().size()) +
                " local subdomains of the transport");
  const std::vector<int>& local = transport.local();
  const auto first = std::find(local.begin(), local.end(), 0);
  restore(systems, first == local.end() ? -1 : static_cast<int>(first - local.begin()));
}

// particles_to: the index of the System that takes every particle (-1: none)
void SplitRestart::restore(const std::vector<System*>& systems, int particles_to) const {
  if (!holds())
    throw Error("SplitRestart::restore: this holds no restart (read one, or restore on the "
                "process that gathered it)");
  for (std::size_t j = 0; j < systems.size(); ++j) {
    System& sys = *systems[j];
    if (sys.particle_count() > 0)
      throw Error("SplitRestart::restore: system " + std::to_string(j) + " holds " +
                  std::to_string(sys.particle_count()) +
                  " particles; give Systems set up alike without particles");
    ParticleStore& store = sys.store();
    if (store.find("subdomain_owner") < 0) store.add_array<int>("subdomain_owner", 1, -1);
    std::istringstream world(world_, std::ios::binary);
    sys.read_state(world);
    sys.remove_particles(std::vector<char>(sys.particle_count(), 1));
    if (static_cast<int>(j) == particles_to)
      for (const std::vector<std::byte>& m : owned_)
        if (!m.empty()) sys.unpack_particles(m.data(), m.size());
    // the hooks' counters over the split: on the System that takes the particles (subdomain
    // 0's), none on the others
    for (std::size_t h = 0; h < hooks_.size() && h < static_cast<std::size_t>(sys.hook_count()); ++h)
      if (!hooks_[h].empty())
        sys.hook(static_cast<int>(h))
            .set_sums(static_cast<int>(j) == particles_to
                          ? hooks_[h]
                          : std::vector<ExactSum>(hooks_[h].size()));
  }
}

}  // namespace partita::dem
