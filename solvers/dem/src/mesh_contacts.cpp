#include "partita/dem/mesh_contacts.hpp"

#include "parallel_pass.hpp"
#include "partita/dem/error.hpp"

#include <algorithm>
#include <numbers>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace partita::dem {

namespace {

std::int64_t feature_key(int mesh, int type, int index) {
  return (static_cast<std::int64_t>(mesh) << 40) | (static_cast<std::int64_t>(type) << 36) |
         static_cast<std::int64_t>(index);
}

}  // namespace

// Contacts of particle i with the meshes, each counted once:
//  - candidates: triangles whose closest point is within R (face, edge or vertex feature) and
//    is a local closest point of the mesh surface (an edge or vertex only where no triangle
//    sharing it comes nearer: on a fine flat mesh only the face under the centre touches);
//  - accepted in the order faces, edges, vertices (then by distance): a face always; an edge
//    only if no accepted face has it as an edge; a vertex only if no accepted face or edge has
//    it; and any contact only if its normal differs from all accepted ones (a sphere cannot
//    touch two surfaces with the same normal: coplanar neighbours sharing the point), and, of
//    another mesh, only if its point is not on an accepted contact's patch, flush with it (two
//    meshes meeting there describe one surface: it touches once).
template <bool Load, bool Energy>
void MeshContacts::evaluate(int i, const Particle& q, const NeighborList& nl,
                            const std::vector<TriangleMesh>& meshes, const ContactModel& model,
                            const Row& row, double dt, bool update_history, Eigen::Vector3d& f,
                            Eigen::Vector3d& t, double& load, DissipationSums* sums,
                            WallDissipation* wd) {
  struct Candidate {
    int mesh, triangle, type, feature;
    TriangleClosestPoint cp;
    double dist2;
    double delta;  // overlap
    bool behind;   // one-sided mesh: the centre behind the face's plane
    Eigen::Vector3d normal;
  };
  // Order of preference: faces, edges, vertices, then by distance (the order of acceptance).
  const auto before = [](const Candidate& a, const Candidate& b) {
    if (a.type != b.type) return a.type < b.type;
    if (a.dist2 != b.dist2) return a.dist2 < b.dist2;
    if (a.mesh != b.mesh) return a.mesh < b.mesh;
    return a.triangle < b.triangle;
  };
  // At most max_candidates touching triangles are kept: when more touch (a fine mesh under a
  // large sphere), the least preferred one gives way, so the faces and the nearest features
  // always take part.
  constexpr int max_candidates = 32;
  Candidate cand[max_candidates + 1];
  int nc = 0;
  int worst = -1;  // index of the least preferred kept candidate once the array is full
  bool any_behind = false;
  // A yielding particle pinched between two faces closer than its diameter less its radius
  // (opposite contacts whose overlaps add to more than r, or a face it has passed facing one it
  // is in front of) is crushed: its load is reported as unbounded (Breakage turns it to powder).
  // Flattened from both sides it is dust; as a sphere it would be pushed into one of the parts.
  bool pinched = false;
  const Eigen::Vector3d& x = q.x;
  const double r = q.r;
  for (int k = nl.mesh_offsets_[i]; k < nl.mesh_offsets_[i + 1]; ++k) {
    const MeshCandidate mc = nl.mesh_candidates_[k];
    const TriangleMesh& m = meshes[mc.mesh];
    if (!m.triangle_active(mc.triangle)) continue;  // its surface has gone
    Candidate& c = cand[nc];  // cand[max_candidates] is scratch once the array is full
    c.cp = m.closest_point(mc.triangle, x);
    c.dist2 = (x - c.cp.point).squaredNorm();
    if (c.dist2 >= r * r || !m.feature_is_local_closest(mc.triangle, c.cp, x)) continue;
    c.mesh = mc.mesh;
    c.triangle = mc.triangle;
    c.type = c.cp.feature;
    c.feature = c.type == TriangleClosestPoint::face ? mc.triangle
                : c.type == TriangleClosestPoint::edge
                    ? m.triangle_edges(mc.triangle)[c.cp.local_index]
                    : m.triangle(mc.triangle)[c.cp.local_index];
    const double dist = std::sqrt(c.dist2);
    if (m.one_sided()) {
      // (TriangleMesh::one_sided(): a face pushes along its outward normal, also a centre that
      // has passed behind it; an edge or vertex touches only from the outer side of the plane)
      const Eigen::Vector3d nt = m.normal(mc.triangle);
      const double s = (x - c.cp.point).dot(nt);
      c.behind = s < 0.0;
      if (c.behind && c.type != TriangleClosestPoint::face) {
        // behind the plane at an edge or vertex: no contact, unless the centre projects onto it
        // (the edge between two coplanar triangles, reached from inside): a face contact
        if (c.dist2 - s * s > 1e-12 * r * r) continue;
        c.type = TriangleClosestPoint::face;
        c.feature = mc.triangle;
      }
      if (c.type == TriangleClosestPoint::face) {
        c.normal = nt;
        c.delta = r - s;
      } else {
        c.normal = dist > 1e-12 * r ? ((x - c.cp.point) / dist).eval() : nt;
        c.delta = r - dist;
      }
      any_behind = any_behind || c.behind;
    } else {
      c.behind = false;
      c.delta = r - dist;
      if (dist > 1e-12 * r) {
        c.normal = (x - c.cp.point) / dist;
      } else {
        const auto& tri = m.triangle(mc.triangle);
        c.normal = (m.position_[tri[1]] - m.position_[tri[0]])
                       .cross(m.position_[tri[2]] - m.position_[tri[0]])
                       .normalized();
      }
    }
    if (nc < max_candidates) {
      ++nc;
      continue;
    }
    if (worst < 0) {
      worst = 0;
      for (int w = 1; w < max_candidates; ++w)
        if (before(cand[worst], cand[w])) worst = w;
    }
    if (before(c, cand[worst])) {
      cand[worst] = c;
      worst = 0;
      for (int w = 1; w < max_candidates; ++w)
        if (before(cand[worst], cand[w])) worst = w;
    }
  }
  if (any_behind) {
    // One-sided meshes: a centre in front of any feature of a mesh within reach is outside its
    // body, and the faces it is behind are the far side of a thin part (a plate thinner than the
    // radius): dropped. A centre behind all is inside the body and leaves through the nearest
    // face (the shallowest: the body's signed distance), not through every face it is behind.
    bool drop[max_candidates + 1] = {};
    for (int c = 0; c < nc; ++c) {
      if (!cand[c].behind) continue;
      for (int o = 0; o < nc && !drop[c]; ++o) {
        if (o == c || cand[o].mesh != cand[c].mesh) continue;
        drop[c] = !cand[o].behind || cand[o].delta < cand[c].delta ||
                  (cand[o].delta == cand[c].delta && o < c);
        // (a face whose point lies in front of the front feature faces it across a gap
        // narrower than the sphere: two parts closing on it, not the far side of a plate)
        if (drop[c] && !cand[o].behind &&
            (cand[c].cp.point - cand[o].cp.point).dot(cand[o].normal) > 0.0)
          pinched = true;
      }
    }
    int kept = 0;
    for (int c = 0; c < nc; ++c)
      if (!drop[c]) cand[kept++] = cand[c];
    nc = kept;
  }
  std::sort(cand, cand + nc, before);
  int accepted[max_contacts];
  int na = 0;
  constexpr double same_normal = 1.0 - 5.0e-5;  // about 0.6 degrees
  constexpr double flush = 0.17;                 // sin(10 degrees)
  for (int c = 0; c < nc; ++c) {
    const Candidate& k = cand[c];
    bool keep = true;
    for (int a = 0; a < na && keep; ++a) {
      const Candidate& acc = cand[accepted[a]];
      if (acc.normal.dot(k.normal) > same_normal) keep = false;
      if (acc.mesh != k.mesh) {
        // another mesh's feature whose point lies on this contact's patch (within its contact
        // radius sqrt(R delta)) and flush with the sphere's tangent plane there: the same
        // surface twice (two interfaces of one body meeting there, their normals apart by more
        // than same_normal: a face of one and the rim edge of the other, or two faces of a
        // deformed surface), which touches the sphere once
        const Eigen::Vector3d d = k.cp.point - acc.cp.point;
        const double d2 = d.squaredNorm();
        if (d2 <= r * acc.delta && std::abs(d.dot(acc.normal)) <= flush * std::sqrt(d2))
          keep = false;
        continue;
      }
      if (acc.type == k.type && acc.feature == k.feature) keep = false;
      const TriangleMesh& m = meshes[k.mesh];
      if (k.type == TriangleClosestPoint::edge && acc.type == TriangleClosestPoint::face) {
        for (int e : m.triangle_edges(acc.triangle)) keep = keep && e != k.feature;
      } else if (k.type == TriangleClosestPoint::vertex) {
        if (acc.type == TriangleClosestPoint::face)
          for (int v : m.triangle(acc.triangle)) keep = keep && v != k.feature;
        else if (acc.type == TriangleClosestPoint::edge)
          for (int v : m.edge(acc.feature)) keep = keep && v != k.feature;
      }
    }
    // (capacity >= min(max_contacts, candidates): the bound is max_contacts)
    if (keep && na < row.capacity) accepted[na++] = c;
  }
  // Histories: the previous step's slots of particle i (its row), matched by feature key.
  std::int64_t* const slot_key = row.key;
  Eigen::Vector3d* const slot_shear = row.shear;
  MeshContactRecord* const records = row.records;
  std::int64_t old_key[max_contacts];
  Eigen::Vector3d old_shear[max_contacts];
  const int n_old = row.count;
  float old_pre[max_contacts];
  for (int s = 0; s < n_old; ++s) {
    old_key[s] = slot_key[s];
    old_shear[s] = slot_shear[s];
    old_pre[s] = records[s].pre_overlap;
  }
  // A contact keeps its history when its feature stays (same key) and also when it passes to
  // a neighbouring feature, rolling or sliding across triangle boundaries, or to another mesh
  // that meets this one there (two interfaces of one body sharing an edge or a face: the twin
  // features have the same normal and one of them holds the contact, whichever is nearer by a
  // rounding): an unmatched old contact whose point (the same material point of its wall, at the
  // current vertex positions) lies within the new contact radius sqrt(R delta) hands its
  // history on - the shear spring and the permanent overlap, which a contact started afresh
  // would lose (its elastic energy made anew, and yielded again).
  int from_old[max_contacts];
  bool old_taken[max_contacts] = {};
  for (int a = 0; a < na; ++a) {
    const Candidate& k = cand[accepted[a]];
    from_old[a] = -1;
    const std::int64_t key = feature_key(k.mesh, k.type, k.feature);
    for (int s = 0; s < n_old; ++s)
      if (old_key[s] == key) from_old[a] = s, old_taken[s] = true;
  }
  for (int a = 0; a < na; ++a) {
    if (from_old[a] >= 0) continue;
    const Candidate& k = cand[accepted[a]];
    double best = r * k.delta;  // (contact radius)^2
    for (int s = 0; s < n_old; ++s) {
      const MeshContactRecord& rec = records[s];
      if (old_taken[s]) continue;
      const TriangleMesh& m = meshes[rec.mesh];
      const auto& tri = m.triangle(rec.triangle);
      const Eigen::Vector3d p = rec.barycentric[0] * m.position_[tri[0]] +
                                rec.barycentric[1] * m.position_[tri[1]] +
                                rec.barycentric[2] * m.position_[tri[2]];
      const double d2 = (p - k.cp.point).squaredNorm();
      if (d2 < best) best = d2, from_old[a] = s;
    }
    if (from_old[a] >= 0) old_taken[from_old[a]] = true;
  }
  for (int a = 0; a < na; ++a) {
    const Candidate& k = cand[accepted[a]];
    const TriangleMesh& m = meshes[k.mesh];
    const std::int64_t key = feature_key(k.mesh, k.type, k.feature);
    Eigen::Vector3d shear =
        from_old[a] >= 0 ? old_shear[from_old[a]] : Eigen::Vector3d::Zero().eval();
    // wall velocity at the contact point: barycentric interpolation of the vertex velocities
    const Eigen::Vector3d v_wall = m.velocity_at(k.triangle, k.cp.barycentric);
    // pre-overlap: a contact made with a triangle that has just entered the contacts keeps its
    // overlap of now; one carried over keeps the smaller of its own and now's (TriangleMesh::
    // triangle_fresh()); the force acts on the overlap beyond it
    // (fresh: also where the contact took over the history of a neighbouring feature's, as a
    // particle in a hole touching its walls does when the face under it is exposed)
    // A centre behind a one-sided face found without history (no contact of the last pass at
    // this point) was inside the body before this contact held it: deeper than r (no contact
    // there) or held by a face that has gone. No motion of this step made that overlap (up to
    // 2 r), so it is a pre-overlap, as under a face that enters the contacts: pushed out with it,
    // the particle would take up to 8/15 E* sqrt(r) (2 r)^(5/2) that nothing worked for. Not at
    // the first pass of a run (q.first_pass), whose contacts, found without history, hold the
    // initial elastic energy.
    const bool found_inside = k.behind && from_old[a] < 0 && !q.first_pass;
    float pre = 0.0f;
    if (m.triangle_fresh(k.triangle) || found_inside)
      pre = static_cast<float>(k.delta);
    else if (from_old[a] >= 0 && old_pre[from_old[a]] > 0.0f)
      pre = std::min(old_pre[from_old[a]], static_cast<float>(k.delta));
    const PairParameters& pp = model.pair(q.material, m.material());
    // yield (yield_overlap()): the overlap beyond the elastic limit adds to the permanent one.
    // Its work is booked where the overlap grows by the contact's own motion, at most twice
    // this step's relative normal approach (reach): a contact found without history deeper
    // than that (the particle was inside before this feature held the contact: another mesh's
    // face behind it, or the nearest face of a body it is inside) has its permanent overlap
    // from before, not from work done now: not booked again; and where a carried contact's
    // overlap grows by more than that, the rest is a jump of the geometry, not worked for (a
    // particle inside a thin part whose way out passes from a shallow face to a deep one and
    // back, or a surface moved without a velocity): only the reach's share is booked.
    const float pre_before = pre;
    const double reach = 2.0 * std::abs((q.v - v_wall).dot(k.normal)) * dt + 1e-9 * r;
    const bool found_deep =
        Energy && from_old[a] < 0 && !m.triangle_fresh(k.triangle) && k.delta > reach;
    double work = 0.0;
    // A particle flattened until its centre reaches the surface (a permanent overlap of its
    // radius) yields no further: it is as compact as it gets there, and beyond it the contact is
    // elastic (Hertz on delta - r), so a fragment pressed against the steel harder than its
    // yield force stays at the face. (Without the bound a centre would sink through the surface
    // under any force above F_y; deeper than r behind it no face touches it, and it would fly on
    // inside the structure and out through the far side.)
    const double delta = yield_overlap(k.delta, r, pp.e_star, q.yield_pressure, pre,
                                       Energy && !found_deep ? &work : nullptr, r);
    if constexpr (Energy) {
      const double growth = static_cast<double>(pre) - static_cast<double>(pre_before);
      wd->plastic += growth > reach ? work * (reach / growth) : work;
    }
    const double cr = r - 0.5 * k.delta;
    Eigen::Vector3d fw, ft;
    DissipativeParts parts;
    const double fn = hertz_mindlin(pp, delta, r, q.m, k.normal, q.v - v_wall, cr * q.w, shear, dt,
                                    update_history, fw, ft, Energy ? &parts : nullptr,
                                    static_cast<double>(pre) - static_cast<double>(pre_before));
    f += fw;
    t -= cr * k.normal.cross(ft);
    if constexpr (Energy) add_wall_parts(parts, k.normal, cr, v_wall, *sums, *wd);
    if (pp.rolling_friction > 0.0) {
      const double wn = q.w.norm();
      if (wn > 0.0) {
        const Eigen::Vector3d tr = (pp.rolling_friction * std::abs(fn) * r / wn) * q.w;
        t -= tr;
        if constexpr (Energy) sums->td -= tr;
      }
    }
    if constexpr (Load) {  // mesh: R* = R
      const double kw = pp.e_star / r;
      load = std::max(load, fn * kw * kw);
    }
    slot_key[a] = key;
    slot_shear[a] = shear;
    MeshContactRecord& rec = records[a];
    rec.mesh = k.mesh;
    rec.triangle = k.triangle;
    rec.barycentric = k.cp.barycentric;
    rec.force = fw;
    rec.delta = delta;
    rec.r_eff = r;
    rec.material = m.material();
    rec.pre_overlap = pre;
  }
  row.count = na;
  if constexpr (Load) {
    if (q.yield_pressure > 0.0) {
      for (int a = 0; a < na && !pinched; ++a)
        for (int b = a + 1; b < na && !pinched; ++b) {
          const Candidate& ka = cand[accepted[a]];
          const Candidate& kb = cand[accepted[b]];
          pinched = ka.normal.dot(kb.normal) < -0.5 && ka.delta + kb.delta > r;
        }
      if (pinched) load = std::numeric_limits<double>::infinity();
    }
  }
}

template void MeshContacts::evaluate<false, false>(int, const Particle&, const NeighborList&,
                                                   const std::vector<TriangleMesh>&,
                                                   const ContactModel&, const Row&, double, bool,
                                                   Eigen::Vector3d&, Eigen::Vector3d&, double&,
                                                   DissipationSums*, WallDissipation*);
template void MeshContacts::evaluate<false, true>(int, const Particle&, const NeighborList&,
                                                  const std::vector<TriangleMesh>&,
                                                  const ContactModel&, const Row&, double, bool,
                                                  Eigen::Vector3d&, Eigen::Vector3d&, double&,
                                                  DissipationSums*, WallDissipation*);
template void MeshContacts::evaluate<true, false>(int, const Particle&, const NeighborList&,
                                                  const std::vector<TriangleMesh>&,
                                                  const ContactModel&, const Row&, double, bool,
                                                  Eigen::Vector3d&, Eigen::Vector3d&, double&,
                                                  DissipationSums*, WallDissipation*);
template void MeshContacts::evaluate<true, true>(int, const Particle&, const NeighborList&,
                                                 const std::vector<TriangleMesh>&,
                                                 const ContactModel&, const Row&, double, bool,
                                                 Eigen::Vector3d&, Eigen::Vector3d&, double&,
                                                 DissipationSums*, WallDissipation*);

// Each contact's reaction shared among its triangle's vertices with the barycentric weights of
// the contact point, particles in order (a fixed summation order); then each triangle's force
// from its vertices' (each vertex's force shared equally among its active triangles; a triangle
// taken out gets none): continuous as a contact moves across triangles, sums preserved (see
// TriangleMesh::triangle_forces).
// Every step, after the force pass. The contacts' scatter to the vertices is serial (a fixed
// order); clearing the vertices and the triangles' shares run in parallel on large meshes (the
// scale case's plate: 160,083 vertices, 105,800 triangles, every DEM step).
void MeshContacts::reduce(std::vector<TriangleMesh>& meshes) const {
  for (TriangleMesh& m : meshes)
    detail::parallel_pass(m.vertex_force_.rows(),
                          [&](Eigen::Index v) { m.vertex_force_.row(v).setZero(); });
  for_each_contact([&](int, const MeshContactRecord& rec, const Eigen::Vector3d&) {
    TriangleMesh& m = meshes[rec.mesh];
    const auto& tri = m.triangle(rec.triangle);
    for (int k = 0; k < 3; ++k)
      m.vertex_force_.row(tri[k]) -= rec.barycentric[k] * rec.force.transpose();
  });
  for (TriangleMesh& m : meshes)
    detail::parallel_pass(m.triangle_count(), [&](int t) {
      if (!m.triangle_active(t)) {  // taken out: its vertices' forces go to the active ones
        m.triangle_force_.row(t).setZero();
        return;
      }
      const auto& tri = m.triangle(t);
      m.triangle_force_.row(t) = m.vertex_share_[tri[0]] * m.vertex_force_.row(tri[0]) +
                                 m.vertex_share_[tri[1]] * m.vertex_force_.row(tri[1]) +
                                 m.vertex_share_[tri[2]] * m.vertex_force_.row(tri[2]);
    });
}

std::size_t MeshContacts::contact_count() const {
  std::size_t n = 0;
  for (int c : count_) n += static_cast<std::size_t>(c);
  return n;
}

// ---- rows: layout, following the particles, state -------------------------------------------

// Room for `rows` rows of `slots` slots in all; a buffer that must grow gets half as much again,
// so that the rows of a bed whose surface layer fluctuates settle after a few builds.
void MeshContacts::start_layout(std::size_t rows, std::size_t slots) {
  const auto room = [](auto& v, std::size_t n) {
    if (v.capacity() < n) v.reserve(n + n / 2);
  };
  room(new_particle_, rows);
  room(new_count_, rows);
  room(new_slot_, rows + 1);
  room(new_key_, slots);
  room(new_shear_, slots);
  room(new_record_, slots);
  new_particle_.clear();
  new_count_.clear();
  new_slot_.assign(1, 0);
  // the slot arrays grow from empty in add_row(): whatever an earlier layout left in them (they
  // are the previous arrays, swapped out) must not survive a layout with fewer slots, nor reach a
  // saved state (a layout without rows kept them, and the state then failed its own check)
  new_key_.clear();
  new_shear_.clear();
  new_record_.clear();
}

void MeshContacts::add_row(int particle, int capacity, int from) {
  new_particle_.push_back(particle);
  new_count_.push_back(from >= 0 ? count_[from] : 0);
  new_slot_.push_back(new_slot_.back() + capacity);
  const std::size_t slots = static_cast<std::size_t>(new_slot_.back());
  // free slots are zero (Eigen's vectors are not initialised by their default constructor, and
  // every slot of a row goes into a saved state)
  new_key_.resize(slots);
  new_shear_.resize(slots, Eigen::Vector3d::Zero());
  new_record_.resize(slots);
  if (from < 0) return;
  const std::size_t src = static_cast<std::size_t>(slot_[from]);
  const std::size_t dst = static_cast<std::size_t>(new_slot_[new_slot_.size() - 2]);
  const std::size_t c = static_cast<std::size_t>(count_[from]);
  std::copy_n(key_.begin() + src, c, new_key_.begin() + dst);
  std::copy_n(shear_.begin() + src, c, new_shear_.begin() + dst);
  std::copy_n(record_.begin() + src, c, new_record_.begin() + dst);
}

void MeshContacts::finish_layout() {
  particle_.swap(new_particle_);
  slot_.swap(new_slot_);
  count_.swap(new_count_);
  key_.swap(new_key_);
  shear_.swap(new_shear_);
  record_.swap(new_record_);
}

// A row for every particle with candidates (ascending); its contacts of the last pass come along
// (both row lists are in particle order: one merge).
void MeshContacts::follow_build(const NeighborList& nl) {
  const int n = static_cast<int>(nl.mesh_offsets_.size()) - 1;
  const int old_rows = static_cast<int>(particle_.size());
  for (int pass = 0; pass < 2; ++pass) {  // count, then lay out
    std::size_t rows = 0, slots = 0;
    int r = 0;
    for (int i = 0; i < n; ++i) {
      const int candidates = nl.mesh_offsets_[i + 1] - nl.mesh_offsets_[i];
      if (candidates == 0) continue;
      while (r < old_rows && particle_[r] < i) ++r;
      const int from = r < old_rows && particle_[r] == i ? r : -1;
      const int capacity =
          std::max(std::min(max_contacts, candidates), from >= 0 ? count_[from] : 0);
      if (pass == 0)
        ++rows, slots += static_cast<std::size_t>(capacity);
      else
        add_row(i, capacity, from);
    }
    if (pass == 0) start_layout(rows, slots);
  }
  finish_layout();
}

void MeshContacts::renumber(const std::vector<int>& new_of_old) {
  if (order_.capacity() < particle_.size()) order_.reserve(particle_.size() * 3 / 2);
  order_.clear();
  for (std::size_t r = 0; r < particle_.size(); ++r) {
    const auto i = static_cast<std::size_t>(particle_[r]);
    const int k = i < new_of_old.size() ? new_of_old[i] : -1;
    if (k >= 0) order_.emplace_back(k, static_cast<int>(r));
  }
  std::sort(order_.begin(), order_.end());
  start_layout(order_.size(), key_.size());
  for (const auto& [k, r] : order_) add_row(k, slot_[r + 1] - slot_[r], r);
  finish_layout();
}

void MeshContacts::write(BinaryWriter& out) const {
  out.array(particle_);
  out.array(slot_);
  out.array(count_);
  out.array(key_);
  out.array(shear_);
  out.array(record_);
}

void MeshContacts::read(BinaryReader& in, std::size_t particles) {
  in.array(particle_, "mesh contact rows");
  in.array(slot_, "mesh contact row slots");
  in.array(count_, "mesh contact counts");
  in.array(key_, "mesh contact features");
  in.array(shear_, "mesh contact histories");
  in.array(record_, "mesh contact records");
  const std::size_t rows = particle_.size();
  bool ok = slot_.size() == rows + 1 && count_.size() == rows && slot_[0] == 0 &&
            static_cast<std::size_t>(slot_.back()) == key_.size() && shear_.size() == key_.size() &&
            record_.size() == key_.size();
  for (std::size_t r = 0; ok && r < rows; ++r)
    ok = particle_[r] >= 0 && static_cast<std::size_t>(particle_[r]) < particles &&
         (r == 0 || particle_[r - 1] < particle_[r]) && slot_[r + 1] >= slot_[r] &&
         slot_[r + 1] - slot_[r] <= max_contacts && count_[r] >= 0 &&
         count_[r] <= slot_[r + 1] - slot_[r];
  if (!ok) throw Error("corrupt state: the mesh contact rows do not agree");
}

// ---- contacts that travel with their particles ----------------------------------------------

void MeshContacts::pack(const std::vector<int>& which, std::vector<std::byte>& out) const {
  for (const int i : which) {
    const auto it = std::lower_bound(particle_.begin(), particle_.end(), i);
    const int r = it != particle_.end() && *it == i ? static_cast<int>(it - particle_.begin()) : -1;
    const std::int32_t count = r >= 0 ? count_[r] : 0;
    std::size_t at = out.size();
    out.resize(at + sizeof count + static_cast<std::size_t>(count) * packed_contact_bytes);
    std::memcpy(out.data() + at, &count, sizeof count);
    at += sizeof count;
    for (int c = 0; c < count; ++c) {
      const auto k = static_cast<std::size_t>(slot_[r] + c);
      std::memcpy(out.data() + at, &key_[k], sizeof(std::int64_t));
      std::memcpy(out.data() + at + 8, shear_[k].data(), 3 * sizeof(double));
      std::memcpy(out.data() + at + 32, &record_[k], sizeof(MeshContactRecord));
      at += packed_contact_bytes;
    }
  }
}

std::size_t MeshContacts::check_packed(const std::byte* data, std::size_t bytes, std::size_t n,
                                       const std::vector<TriangleMesh>& meshes) {
  std::size_t at = 0;
  for (std::size_t p = 0; p < n; ++p) {
    std::int32_t count = 0;
    if (bytes - at < sizeof count)
      throw Error("the mesh contacts of particle " + std::to_string(p) +
                  " of the message are cut short");
    std::memcpy(&count, data + at, sizeof count);
    at += sizeof count;
    if (count < 0 || count > max_contacts)
      throw Error("particle " + std::to_string(p) + " of the message has " + std::to_string(count) +
                  " mesh contacts; a particle keeps 0 to " + std::to_string(max_contacts));
    if ((bytes - at) / packed_contact_bytes < static_cast<std::size_t>(count))
      throw Error("the mesh contacts of particle " + std::to_string(p) +
                  " of the message are cut short");
    for (int c = 0; c < count; ++c, at += packed_contact_bytes) {
      MeshContactRecord rec;
      std::memcpy(static_cast<void*>(&rec), data + at + 32, sizeof rec);
      const bool mesh_ok = rec.mesh >= 0 && rec.mesh < static_cast<int>(meshes.size());
      if (!mesh_ok || rec.triangle < 0 || rec.triangle >= meshes[rec.mesh].triangle_count())
        throw Error("particle " + std::to_string(p) + " of the message touches triangle " +
                    std::to_string(rec.triangle) + " of mesh " + std::to_string(rec.mesh) +
                    ", which this system does not have (" + std::to_string(meshes.size()) +
                    " meshes): set the receiver up with the sender's meshes");
    }
  }
  return at;
}

void MeshContacts::unpack(int first, std::size_t n, const std::byte* data) {
  // the counts first (rows only for particles with contacts), then the layout: the rows there
  // are, followed by the new particles' rows
  std::size_t rows = particle_.size(), slots = key_.size();
  std::size_t at = 0;
  for (std::size_t p = 0; p < n; ++p) {
    std::int32_t count = 0;
    std::memcpy(&count, data + at, sizeof count);
    at += sizeof count + static_cast<std::size_t>(count) * packed_contact_bytes;
    if (count > 0) ++rows, slots += static_cast<std::size_t>(count);
  }
  start_layout(rows, slots);
  for (std::size_t r = 0; r < particle_.size(); ++r)
    add_row(particle_[r], slot_[r + 1] - slot_[r], static_cast<int>(r));
  at = 0;
  for (std::size_t p = 0; p < n; ++p) {
    std::int32_t count = 0;
    std::memcpy(&count, data + at, sizeof count);
    at += sizeof count;
    if (count == 0) continue;
    add_row(first + static_cast<int>(p), count, -1);
    new_count_.back() = count;
    const auto dst = static_cast<std::size_t>(new_slot_[new_slot_.size() - 2]);
    for (int c = 0; c < count; ++c, at += packed_contact_bytes) {
      std::memcpy(&new_key_[dst + c], data + at, sizeof(std::int64_t));
      std::memcpy(new_shear_[dst + c].data(), data + at + 8, 3 * sizeof(double));
      std::memcpy(static_cast<void*>(&new_record_[dst + c]), data + at + 32,
                  sizeof(MeshContactRecord));
    }
  }
  finish_layout();
}

}  // namespace partita::dem
