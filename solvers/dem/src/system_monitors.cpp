// System: monitors (energies, forces, contact counts).
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/parallel.hpp"

#include <algorithm>
#include <cstddef>
#include <sstream>
#include <vector>

namespace partita::dem {

namespace {

// sum_i term(i) over n particles in a fixed order whatever the number of threads: chunks of
// parallel_pass_min particles summed in ascending i (in parallel), then the chunks' sums in
// ascending order. (One chunk below that size: the plain ascending sum.)
template <class Term>
double ordered_sum(std::ptrdiff_t n, Term term) {
  const std::ptrdiff_t chunk = parallel_pass_min;
  const std::ptrdiff_t chunks = (n + chunk - 1) / chunk;
  // the chunks' sums: the calling thread's buffer, kept between calls (no allocation in a step),
  // shared with the team by a plain pointer (each thread's `scratch` is its own)
  thread_local std::vector<double> scratch;
  scratch.assign(static_cast<std::size_t>(chunks), 0.0);
  double* const part = scratch.data();
#pragma omp parallel for schedule(static) if (chunks > 1)
  for (std::ptrdiff_t c = 0; c < chunks; ++c) {
    double s = 0.0;
    for (std::ptrdiff_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) s += term(i);
    part[c] = s;
  }
  double total = 0.0;
  for (std::ptrdiff_t c = 0; c < chunks; ++c) total += part[c];
  return total;
}

}  // namespace

// ---- monitors ---------------------------------------------------------------------------------

// (Read from the packed state while it is ahead of the store's: no pass to copy it back first.
// The same values either way.)
double System::kinetic_energy() const {
  const Particles& p = store_.core();
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  if (const PackedParticle* q = verlet_.ahead())
    return ordered_sum(n, [&](std::ptrdiff_t i) {
      return 0.5 * p.mass[i] * q[i].v.squaredNorm() + 0.5 * p.inertia[i] * q[i].w.squaredNorm();
    });
  return ordered_sum(n, [&](std::ptrdiff_t i) {
    return 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
           0.5 * p.inertia[i] * p.angular_velocity[i].squaredNorm();
  });
}

Eigen::Vector3d System::linear_momentum() const {
  const Particles& p = store_.core();
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const PackedParticle* q = verlet_.ahead();
  Eigen::Vector3d out;
  for (int k = 0; k < 3; ++k)
    out[k] = q != nullptr
                 ? ordered_sum(n, [&](std::ptrdiff_t i) { return p.mass[i] * q[i].v[k]; })
                 : ordered_sum(n, [&](std::ptrdiff_t i) { return p.mass[i] * p.velocity[i][k]; });
  return out;
}

double System::half_step_term(double dt) const {
  const Particles& p = store_.core();
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const double h = 0.5 * dt, h2 = 0.125 * dt * dt;
  auto term = [&](std::ptrdiff_t i, const Eigen::Vector3d& f, const Eigen::Vector3d& t,
                  const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
    return h * (f.dot(v) + t.dot(w)) +
           h2 * (f.squaredNorm() / p.mass[i] + t.squaredNorm() / p.inertia[i]);
  };
  // the walls' and meshes' side: the work of the last pass's contact forces over half a step of
  // the walls' motion, which the steps' sum F_k . v_wall dt counts beyond the trapezoidal rule
  double walls = walls_.power();
  mesh_contacts_.for_each_contact([&](int, const MeshContactRecord& rec, const Eigen::Vector3d&) {
    walls += rec.force.dot(meshes_[rec.mesh].velocity_at(rec.triangle, rec.barycentric));
  });
  walls *= h;
  if (const PackedParticle* q = verlet_.ahead())
    return walls + ordered_sum(n, [&](std::ptrdiff_t i) {
             return term(i, q[i].f, q[i].t, q[i].v, q[i].w);
           });
  return walls + ordered_sum(n, [&](std::ptrdiff_t i) {
           return term(i, p.force[i], p.torque[i], p.velocity[i], p.angular_velocity[i]);
         });
}

double System::potential_energy() const {
  sync_particles();
  const Particles& p = store_.core();
  return -ordered_sum(static_cast<std::ptrdiff_t>(p.size()), [&](std::ptrdiff_t i) {
    return p.mass[i] * gravity_.dot(p.position[i]);
  });
}

double System::elastic_energy() const {
  sync_particles();
  const_cast<ContactModel&>(model_).update();
  const Particles& p = store_.core();
  const std::vector<Eigen::Vector3d>& plane_shear = walls_.shear(store_);
  const std::vector<PlaneWall>& planes = walls_.planes();
  double e = 0.0;
  const int n = static_cast<int>(p.size());
  const Eigen::Vector3d no_shear = Eigen::Vector3d::Zero();
  auto pair_energy = [&](int i, int j, const Eigen::Vector3d& shear, double plastic) {
    const double rsum = p.radius[i] + p.radius[j];
    const double delta = rsum - (p.position[i] - p.position[j]).norm();
    if (delta <= 0.0) return 0.0;
    return hertz_elastic_energy(model_.pair(p.material[i], p.material[j]),
                                elastic_overlap(delta, plastic), p.radius[i] * p.radius[j] / rsum,
                                shear);
  };
  // The contacts of the last force pass, with their histories. Without lists for the present
  // particles (before the first step, or after a change of the particle set until the next step)
  // the pairs of the moment from a scratch neighbour search (skin 0: the touching pairs), each
  // with the history the next list build will hand it (that of a pair the renumbered rows still
  // hold; none for a new pair); the meshes' contacts then are the last pass's (the particles
  // still there, as the next pass starts from them) or, before the first pass, those of the
  // moment, found as the first pass will find them (the force pass's own selection: a face, edge
  // or vertex shared by several triangles counted once), without histories (new contacts have
  // none). So the energy after a change is the one the next step starts from.
  const NeighborList& lists = neighbors_;
  const bool current = lists_current_ && lists.offsets_.size() == p.size() + 1;
  NeighborList scratch;
  if (!current) scratch.search(p, planes, meshes_);
  const NeighborList& nl = current ? lists : scratch;
  const int kept_rows = current || pairs_.slot_count() != lists.neighbors_.size()
                            ? 0
                            : static_cast<int>(lists.offsets_.size()) - 1;
  // the slot of the kept pair (i, j), or -1
  auto kept_slot = [&](int i, int j) -> std::ptrdiff_t {
    if (i >= kept_rows) return -1;
    const auto first = lists.neighbors_.begin() + lists.offsets_[i];
    const auto last = lists.neighbors_.begin() + lists.offsets_[i + 1];
    const auto at = std::lower_bound(first, last, j);
    if (at == last || *at != j) return -1;
    return at - lists.neighbors_.begin();
  };
  for (int i = 0; i < n; ++i)
    for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
      const int j = nl.neighbors_[s];
      if (current) {
        e += pair_energy(i, j, pairs_.shear(s), pairs_.plastic(s));
      } else {
        const std::ptrdiff_t k = kept_slot(i, j);
        e += k < 0 ? pair_energy(i, j, no_shear, 0.0)
                   : pair_energy(i, j, pairs_.shear(static_cast<std::size_t>(k)),
                                 pairs_.plastic(static_cast<std::size_t>(k)));
      }
    }
  const std::size_t np = planes.size();
  const bool have_shear = plane_shear.size() == p.size() * np;
  for (int i = 0; i < n; ++i)
    for (std::size_t k = 0; k < np; ++k) {
      const double delta = p.radius[i] - (p.position[i] - planes[k].point).dot(planes[k].normal);
      if (delta <= 0.0) continue;
      e += hertz_elastic_energy(model_.pair(p.material[i], planes[k].material), delta, p.radius[i],
                                have_shear ? plane_shear[i * np + k] : no_shear);
    }
  auto mesh_energy = [&](int i, const MeshContactRecord& rec, const Eigen::Vector3d& shear) {
    e +=
        hertz_elastic_energy(model_.pair(p.material[i], rec.material), rec.delta, rec.r_eff, shear);
  };
  if (current || steps_ > 0)
    mesh_contacts_.for_each_contact(mesh_energy);
  else
    MeshContacts::for_each_contact_now(
        p, nl, meshes_, model_,
        [&](int i, const MeshContactRecord& rec) { mesh_energy(i, rec, no_shear); });
  return e;
}

Eigen::Vector3d System::wall_force(int wall) const {
  return walls_.wall_force(wall);
}

Eigen::Vector3d System::mesh_force(int mesh) const {
  check_mesh(mesh, "mesh_force");
  return meshes_[mesh].total_force();
}

const Eigen::MatrixX3d& System::triangle_forces(int mesh) const {
  check_mesh(mesh, "triangle_forces");
  return meshes_[mesh].triangle_forces();
}

const Eigen::MatrixX3d& System::vertex_forces(int mesh) const {
  check_mesh(mesh, "vertex_forces");
  return meshes_[mesh].vertex_forces();
}

std::size_t System::contact_count() const {
  sync_particles();
  const Particles& p = store_.core();
  const NeighborList& nl = neighbors_;
  if (nl.offsets_.size() != p.size() + 1) return 0;
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  std::size_t count = 0;  // (an integer: the same in any order)
#pragma omp parallel for schedule(static) reduction(+ : count) if (n >= parallel_pass_min)
  for (std::ptrdiff_t i = 0; i < n; ++i)
    for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
      const int j = nl.neighbors_[s];
      const double rsum = p.radius[i] + p.radius[j];
      if ((p.position[i] - p.position[j]).squaredNorm() < rsum * rsum) ++count;
    }
  return count;
}

std::ptrdiff_t System::first_particle_astray(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                             double margin) const {
  const Particles& p = store_.core();
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const PackedParticle* q = verlet_.ahead();  // (as kinetic_energy())
  std::ptrdiff_t first = n;
#pragma omp parallel for schedule(static) reduction(min : first) if (n >= parallel_pass_min)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& x = q ? q[i].x : p.position[i];
    const Eigen::Vector3d& v = q ? q[i].v : p.velocity[i];
    if (!x.allFinite() || !v.allFinite() ||
        std::max((lo - x).maxCoeff(), (x - hi).maxCoeff()) > margin)
      first = std::min(first, i);
  }
  return first < n ? first : -1;
}

double System::mean_contacts_per_particle() const {
  return store_.size() == 0 ? 0.0 : 2.0 * contact_count() / store_.size();
}

}  // namespace partita::dem
