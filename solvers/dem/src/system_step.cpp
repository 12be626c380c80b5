// System: the step (velocity Verlet), the force pass (pairs, planes, meshes) and the reductions.
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/mesh_contacts.hpp"
#include "partita/dem/parallel.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>

namespace partita::dem {

namespace {

constexpr int block_size = ThreadPartition::block_size;

}  // namespace

// ---- time stepping ----------------------------------------------------------------------------

void System::step(double dt) {
  prepare();
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "step: the time step must be > 0 s, got " << dt;
    throw Error(msg.str());
  }
  if (dt > rayleigh_dt_ * (1.0 + 1e-12)) {
    std::ostringstream msg;
    msg.precision(6);
    msg << "step: time step " << dt << " s is above the Rayleigh time step " << rayleigh_dt_
        << " s of the smallest particle; use a fraction of it (typically 0.1-0.3, "
        << "rayleigh_time_step())";
    throw Error(msg.str());
  }
  if (!packed_valid_) load_packed();
  if (!forces_valid_) {
    compute_forces(dt, false, 0.0, false);
    forces_valid_ = true;
  }
  for (TriangleMesh& m : meshes_) {
    if (!m.velocity_from_motion_) continue;
    for (int v = 0; v < m.vertex_count(); ++v)
      m.velocity_[v] = (m.position_[v] - m.position_last_step_[v]) / dt;
  }
  Particles& p = store_.core();
  const double half = 0.5 * dt;
  const std::vector<Eigen::Vector3d>& x_build = neighbors_.position_at_build_;
  const bool have_build = x_build.size() == p.size();
  double moved2 = 0.0;  // largest squared displacement since the last neighbour build
  bool rebuild = !have_build;
  for (PlaneWall& w : planes_) w.point += dt * w.velocity;
  const int parts = set_partition();
  partition_.prepare_cross_pairs(neighbors_);  // for the current lists (a rebuild below: its own)
  // One parallel region for the whole step unless the lists need a rebuild: velocity Verlet,
  // first half (v += dt/2 F/m, x += dt v, omega += dt/2 T/I on packed_, F = m g, T = 0), then the
  // forces at t + dt and the second half (v += dt/2 F/m, omega += dt/2 T/I) particle by particle
  // as each total is complete. With a rebuild the region
  // ends after the first half and the (parallel) build and force evaluation follow. Every loop
  // runs over the same parts (thread t: part t), so a particle's data stays in one core's cache.
#pragma omp parallel if (parts > 1) num_threads(parts)
  {
#pragma omp for schedule(static, 1) reduction(max : moved2)
    for (int part = 0; part < parts; ++part) {
      for (int i = partition_.begin(part); i < partition_.begin(part + 1); ++i) {
        PackedParticle& q = packed_[i];
        q.v += (half / q.m) * p.force[i];
        q.x += dt * q.v;
        q.w += (half / p.inertia[i]) * p.torque[i];
        if (have_build) moved2 = std::max(moved2, (q.x - x_build[i]).squaredNorm());
        start_sums(i);
      }
    }
    // moved2 is complete after the loop's barrier; every thread reaches the same decision
    const bool rebuild_here = !have_build || neighbors_.needs_rebuild(moved2, planes_, meshes_);
    if (!rebuild_here) evaluate_forces(dt, true, half);
#pragma omp master
    rebuild = rebuild_here;
  }
  if (rebuild) {
    if (sort_interval_ > 0 && ++builds_since_sort_ >= sort_interval_) reorder_particles();
    rebuild_lists();
    compute_forces(dt, true, half, true);
  } else {
    reduce_wall_and_mesh_forces();
  }
  mirror_valid_ = false;
  for (TriangleMesh& m : meshes_) m.position_last_step_ = m.position_;
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].post_force(*this, dt);
  time_ += dt;
  ++steps_;
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].end_of_step(*this, dt);
}

void System::run(long steps, double dt) {
  for (long s = 0; s < steps; ++s) step(dt);
}

// ---- forces -----------------------------------------------------------------------------------

// Positions, velocities and angular velocities live in packed_ while stepping (with what the pair
// loop reads about a neighbour: 96 bytes per particle, 2 cache lines instead of one per array);
// the store's arrays mirror them for the caller, copied on demand.
void System::load_packed() {
  const Particles& p = store_.core();
  const int n = static_cast<int>(p.size());
  packed_.resize(n);
  for (int i = 0; i < n; ++i) {
    PackedParticle& q = packed_[i];
    q.x = p.position[i], q.v = p.velocity[i], q.w = p.angular_velocity[i];
    q.r = p.radius[i], q.m = p.mass[i], q.material = p.material[i];
  }
  packed_valid_ = true;
  mirror_valid_ = true;
}

void System::sync_particles() const {
  if (mirror_valid_) return;
  Particles& p = store_.core();
  for (std::size_t i = 0; i < packed_.size(); ++i) {
    p.position[i] = packed_[i].x;
    p.velocity[i] = packed_[i].v;
    p.angular_velocity[i] = packed_[i].w;
  }
  mirror_valid_ = true;
}

// Starts the force sums of a step: F = m g, T = 0.
void System::start_sums(int i) {
  Particles& p = store_.core();
  p.force[i] = packed_[i].m * gravity_;
  p.torque[i].setZero();
  if (track_load_) load_[i] = 0.0;
}

void System::compute_forces(double dt, bool update_history, double kick, bool started) {
  if (!packed_valid_) load_packed();
  const int parts = set_partition();
  partition_.prepare_cross_pairs(neighbors_);
#pragma omp parallel if (parts > 1) num_threads(parts)
  {
    if (!started) {
#pragma omp for schedule(static, 1)
      for (int part = 0; part < parts; ++part)
        for (int i = partition_.begin(part); i < partition_.begin(part + 1); ++i) start_sums(i);
    }
    evaluate_forces(dt, update_history, kick);
  }
  reduce_wall_and_mesh_forces();
}

// Hertz-Mindlin force of the pair in slot s (i < j): F on i, the torques on i and j. Returns
// false (and settles the history) when the spheres do not overlap. Torques T_i = -cr_i n x F_t,
// T_j = -cr_j n x F_t (cr = R - delta/2, LIGGGHTS convention), rolling resistance
// T_i = -mu_r F_n R* w_rel/|w_rel| = -T_j (w_rel = omega_i - omega_j).
// Load: also the contact load F_n (E*/R*)^2 (breakage criterion, System::contact_load()).
template <bool Load>
PARTITA_DEM_INLINE bool System::pair_force(const PackedParticle& qi, int j, int s, double dt,
                                           bool update_history, Eigen::Vector3d& fij,
                                           Eigen::Vector3d& ti, Eigen::Vector3d& tj, double& load) {
  NeighborList& nl = neighbors_;
  const PackedParticle& qj = packed_[j];
  const Eigen::Vector3d d = qi.x - qj.x;
  const double ri = qi.r, rj = qj.r;
  const double rsum = ri + rj;
  const double r2 = d.squaredNorm();
  if (r2 >= rsum * rsum) {
    if (nl.touching_[s]) {
      nl.touching_[s] = 0;
      nl.shear_[s].setZero();
    }
    return false;
  }
  nl.touching_[s] = 1;
  const double r = std::sqrt(r2);
  const Eigen::Vector3d nrm = r > 0.0 ? Eigen::Vector3d(d * (1.0 / r)) : Eigen::Vector3d::UnitZ();
  const double delta = rsum - r;
  const double mi = qi.m, mj = qj.m;
  const PairParameters& pp = model_.pair(qi.material, qj.material);
  const double r_eff = ri * rj / rsum;
  const double m_eff = mi * mj / (mi + mj);
  const double cri = ri - 0.5 * delta, crj = rj - 0.5 * delta;
  const Eigen::Vector3d w_arm = cri * qi.w + crj * qj.w;
  Eigen::Vector3d ft;
  const double fn = hertz_mindlin(pp, delta, r_eff, m_eff, nrm, qi.v - qj.v, w_arm, nl.shear_[s],
                                  dt, update_history, fij, ft);
  if constexpr (Load) {
    const double k = pp.e_star / r_eff;
    load = fn * k * k;
  }
  const Eigen::Vector3d c = nrm.cross(ft);
  ti = -cri * c;
  tj = -crj * c;
  if (pp.rolling_friction > 0.0) {
    const Eigen::Vector3d w_rel = qi.w - qj.w;
    const double wn = w_rel.norm();
    if (wn > 0.0) {
      const Eigen::Vector3d tr = (-pp.rolling_friction * std::abs(fn) * r_eff / wn) * w_rel;
      ti += tr;
      tj -= tr;
    }
  }
  return true;
}

// Called inside a parallel region. Each particle's force is a sum in a fixed order, whatever the
// number of threads: F_i = m_i g (start_sums()) + the pairs (k, i), k < i, in ascending k + the
// pairs (i, j), j > i, in ascending j + planes + meshes. Rows are processed in ascending i, so the
// pairs (k, i) have all been added when row i starts and i's total is complete at the end of its
// row. Part t owns the particles [begin(t), begin(t+1)) of partition_ and adds pair forces to j
// directly when j is its own; pairs reaching into a later part (cross pairs) are evaluated first,
// each once, into its cross_force, then added by both owners in the same place of their sums.
void System::evaluate_forces(double dt, bool update_history, double kick) {
  if (track_load_)
    evaluate_forces_impl<true>(dt, update_history, kick);
  else
    evaluate_forces_impl<false>(dt, update_history, kick);
}

template <bool Load>
void System::evaluate_forces_impl(double dt, bool update_history, double kick) {
  Particles& p = store_.core();
  const NeighborList& nl = neighbors_;
  ThreadPartition& tp = partition_;
  const int parts = tp.parts();
  std::vector<Eigen::Vector3d>& plane_shear = store_.array<Eigen::Vector3d>(h_plane_shear_);
  double* load = Load ? load_.data() : nullptr;
  const MeshContacts::History mesh_history{store_.array<int>(h_mesh_slot_count_).data(),
                                           store_.array<std::int64_t>(h_mesh_slot_key_).data(),
                                           store_.array<Eigen::Vector3d>(h_mesh_slot_shear_).data(),
                                           store_.array<MeshContactRecord>(h_mesh_records_).data()};
  const int np = static_cast<int>(planes_.size());
  const bool have_meshes = !meshes_.empty();
  if (parts > 1) {  // the cross pairs, shared evenly among the threads
    const int n_cross = static_cast<int>(tp.cross_pairs.size());
#pragma omp for schedule(static)
    for (int k = 0; k < n_cross; ++k) {
      const ThreadPartition::CrossPair& c = tp.cross_pairs[k];
      ThreadPartition::CrossForce& cf = tp.cross_force[k];
      cf.touching = pair_force<Load>(packed_[c.i], c.j, c.slot, dt, update_history, cf.force_i,
                                     cf.torque_i, cf.torque_j, cf.load);
    }
  }
#pragma omp for schedule(static, 1)
  for (int part = 0; part < parts; ++part) {
    // pairs (k, i) from earlier parts, ascending k
    for (int k = tp.cross_in_begin[part]; k < tp.cross_in_begin[part + 1]; ++k) {
      const int c = tp.cross_in[k];
      const ThreadPartition::CrossForce& cf = tp.cross_force[c];
      if (!cf.touching) continue;
      const int j = tp.cross_pairs[c].j;
      p.force[j] -= cf.force_i;
      p.torque[j] += cf.torque_j;
      if constexpr (Load) load[j] = std::max(load[j], cf.load);
    }
    int cross = tp.cross_out_begin[part];
    const int lo = tp.begin(part), hi = tp.begin(part + 1);
    for (int b = lo / block_size; b * block_size < hi; ++b) {
      // plane forces summed per block of particles, then over blocks (fixed order)
      Eigen::Vector3d* block_wall = wall_block_force_.data() + static_cast<std::size_t>(b) * np;
      for (int k = 0; k < np; ++k) block_wall[k].setZero();
      const int i_end = std::min(hi, (b + 1) * block_size);
      for (int i = b * block_size; i < i_end; ++i) {
        PackedParticle& qi = packed_[i];
        Eigen::Vector3d f = p.force[i];
        Eigen::Vector3d t = p.torque[i];
        double load_i = Load ? load[i] : 0.0;
        for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
          const int j = nl.neighbors_[s];
          if (j >= hi) {  // a cross pair, already evaluated
            const ThreadPartition::CrossForce& cf = tp.cross_force[cross++];
            if (cf.touching) {
              f += cf.force_i, t += cf.torque_i;
              if constexpr (Load) load_i = std::max(load_i, cf.load);
            }
            continue;
          }
          Eigen::Vector3d fij, ti, tj;
          double lij = 0.0;
          if (!pair_force<Load>(qi, j, s, dt, update_history, fij, ti, tj, lij)) continue;
          f += fij;
          t += ti;
          p.force[j] -= fij;
          p.torque[j] += tj;
          if constexpr (Load) {
            load_i = std::max(load_i, lij);
            load[j] = std::max(load[j], lij);
          }
        }
        // Planes near i: overlap delta = R - (x - x_w).n_w, R* = R, m* = m.
        const double ri = qi.r;
        std::uint64_t mask = np <= 64 ? nl.plane_mask_[i] : 0;
        for (int k = 0; k < np; ++k) {
          if (np <= 64) {  // jump to the next plane near i
            if (mask == 0) break;
            k = std::countr_zero(mask);
            mask &= mask - 1;
          }
          const PlaneWall& w = planes_[k];
          Eigen::Vector3d& shear = plane_shear[static_cast<std::size_t>(i) * np + k];
          const double delta = ri - (qi.x - w.point).dot(w.normal);
          if (delta <= 0.0) {
            shear.setZero();
            continue;
          }
          const PairParameters& pp = model_.pair(qi.material, w.material);
          const double cr = ri - 0.5 * delta;
          Eigen::Vector3d fw, ft;
          const double fn = hertz_mindlin(pp, delta, ri, qi.m, w.normal, qi.v - w.velocity,
                                          cr * qi.w, shear, dt, update_history, fw, ft);
          f += fw;
          t -= cr * w.normal.cross(ft);
          if (pp.rolling_friction > 0.0) {
            const double wn = qi.w.norm();
            if (wn > 0.0) t -= (pp.rolling_friction * std::abs(fn) * ri / wn) * qi.w;
          }
          if constexpr (Load) {  // wall: R* = R
            const double kw = pp.e_star / ri;
            load_i = std::max(load_i, fn * kw * kw);
          }
          block_wall[k] -= fw;
        }
        if (have_meshes) {  // own accumulators: f and t keep their registers
          Eigen::Vector3d fm = Eigen::Vector3d::Zero(), tm = Eigen::Vector3d::Zero();
          const MeshContacts::Particle q{qi.x, qi.r, qi.v, qi.m, qi.w, qi.material};
          MeshContacts::evaluate<Load>(i, q, nl, meshes_, model_, mesh_history, dt, update_history,
                                       fm, tm, load_i);
          f += fm;
          t += tm;
        }
        p.force[i] = f;
        p.torque[i] = t;
        if constexpr (Load) load[i] = load_i;
        if (kick > 0.0) {  // (no other row reads particle i any more in this pass)
          qi.v += (kick / qi.m) * f;
          qi.w += (kick / p.inertia[i]) * t;
        }
      }
    }
  }
}

void System::reduce_wall_and_mesh_forces() {
  const int n = static_cast<int>(store_.size());
  const int np = static_cast<int>(planes_.size());
  const int blocks = (n + block_size - 1) / block_size;
  // Wall totals (fixed order: blocks, then planes).
  for (Eigen::Vector3d& w : wall_force_) w.setZero();
  for (int b = 0; b < blocks; ++b)
    for (int k = 0; k < np; ++k)
      wall_force_[planes_[k].wall] += wall_block_force_[static_cast<std::size_t>(b) * np + k];
  // Mesh forces: particles in order (MeshContacts::reduce).
  if (meshes_.empty()) return;
  MeshContacts::reduce(n, store_.array<int>(h_mesh_slot_count_).data(),
                       store_.array<MeshContactRecord>(h_mesh_records_).data(), meshes_);
}

}  // namespace partita::dem
