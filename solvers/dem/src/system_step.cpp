// System: the step (orchestrating the VelocityVerlet integrator), the force pass (pairs, planes,
// meshes) and the reductions.
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/mesh_contacts.hpp"
#include "partita/dem/parallel.hpp"
#include "motion_bound.hpp"
#include "parallel_pass.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace partita::dem {

namespace {

constexpr int block_size = ThreadPartition::block_size;
constexpr int cross_chunk = 64;  // cross pairs a chunk of the force pass (stack arrays: ~6 KB)

// the step profile's clock [ns]
std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

// ---- time stepping ----------------------------------------------------------------------------

void System::step(double dt) {
  const std::int64_t profile_start = profiling_ ? now_ns() : 0;
  prepare();
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "step: the time step must be > 0 s, got " << dt;
    throw Error(msg.str());
  }
  // A step may exceed the Rayleigh step by the coupling's window tolerance (1e-9 relative,
  // partita::coupling::TimeWindow::tolerance, which the DEM cannot name): a window split into
  // substeps of at most the Rayleigh step gives substeps up to that much longer.
  constexpr double kStepTolerance = 1e-9;
  if (dt > rayleigh_dt_ * (1.0 + kStepTolerance)) {
    std::ostringstream msg;
    msg.precision(6);
    msg << "step: time step " << dt << " s is above the Rayleigh time step " << rayleigh_dt_
        << " s of the smallest particle; use a fraction of it (typically 0.1-0.3, "
        << "rayleigh_time_step())";
    throw Error(msg.str());
  }
  if (!verlet_.loaded()) verlet_.load(store_.core());
  verlet_.moved();  // from here on the packed copy is ahead of the store's
  if (!forces_valid_) {
    compute_forces(dt, false, 0.0, false);
    forces_valid_ = true;
  }
  if (energy_tracking_) {  // (outside the timed loops: once, and after a change of the set)
    Energies& e = energies_;
    if (!e.started) {
      e.started = true;
      energy_dt_ = dt;
      e.kinetic_start = kinetic_energy() + half_step_term(dt);
      e.elastic_start = elastic_energy();
    }
    settle_set_change();
    if (dt != energy_dt_) {  // the half-step term of the state now, at the new step
      e.kinetic_start += half_step_term(dt) - half_step_term(energy_dt_);
      energy_dt_ = dt;
    }
    if (e.wall_work.size() != static_cast<std::size_t>(walls_.wall_count()))
      e.wall_work.resize(static_cast<std::size_t>(walls_.wall_count()), 0.0);
    if (e.mesh_work.size() != meshes_.size()) e.mesh_work.resize(meshes_.size(), 0.0);
    verlet_.moved();  // (elastic_energy() brought the store's copies up to date: they fall
                      // behind again with this step)
  }
  // (the mesh loops of a step run on the threads for large meshes: the scale case's plate has
  // 160,083 vertices, a serial pass over them each step would limit the thread scaling)
  for (TriangleMesh& m : meshes_) {
    if (!m.velocity_from_motion_) continue;
    detail::parallel_pass(m.vertex_count(), [&](int v) {
      m.velocity_[v] = (m.position_[v] - m.position_last_step_[v]) / dt;
    });
  }
  Particles& p = store_.core();
  const double half = 0.5 * dt;
  const std::vector<Eigen::Vector3d>& x_build = neighbors_.position_at_build_;
  const bool have_build = x_build.size() == p.size();
  double moved2 = 0.0;  // largest squared displacement since the last neighbour build
  bool rebuild = !have_build;
  walls_.advance(dt);
  const int parts = set_partition();
  partition_.prepare_cross_pairs(neighbors_);  // for the current lists (a rebuild below: its own)
  start_load_pass(parts);
  // Without a rebuild, one parallel region does the whole step: the integrator's first half
  // (VelocityVerlet: v += dt/2 F/m, x += dt v, omega += dt/2 T/I), the start of the force sums
  // (F = m g, T = 0), then the forces at t + dt and the integrator's kick (v += dt/2 F/m,
  // omega += dt/2 T/I) particle by particle as each total is complete. Every loop runs over the
  // same parts (thread t: part t), so a particle's data stays in one core's cache.
  // When the last step's motion bound shows that this first half cannot move a particle beyond
  // the skin, the first half runs inside the force pass, each particle just before the first row
  // that reads it: the particle's two cache lines are read once per step instead of twice (a
  // pass of its own over a bed larger than the L2 cache reads them back from L3). Otherwise the
  // first half is a loop of its own, then the exact decision: forces, or rebuild and forces.
  // Both give the same bits: the first half, the rebuild decision and every force sum are the
  // same operations in the same order.
  bool fused = false;
  double bound = 0.0;  // fused: no particle is further than this from its position at the build
  if (have_build && verlet_.has_motion()) {
    bound = detail::motion_bound(verlet_.motion(), dt);
    fused = !neighbors_.needs_rebuild(bound * bound, walls_.planes(), meshes_);
  }
  if (fused) {
    std::int64_t fork = 0;
    if (profiling_) {
      for (int t = 0; t < parts; ++t) marks_[t].enter = 0;  // (set by the threads of the team)
      fork = now_ns();
    }
#pragma omp parallel if (parts > 1) num_threads(parts)
    evaluate_forces(dt, true, half, true);
    if (profiling_) record_fused_pass(fork, now_ns(), parts);
    reduce_wall_and_mesh_forces(dt, true);
  } else {
    const VelocityVerlet::Pass verlet = verlet_.pass(p);
#pragma omp parallel if (parts > 1) num_threads(parts)
    {
#pragma omp for schedule(static, 1) reduction(max : moved2)
      for (int part = 0; part < parts; ++part) {
        for (int i = partition_.begin(part); i < partition_.begin(part + 1); ++i) {
          const Eigen::Vector3d& x = verlet.first_half(i, dt, half);
          if (have_build) moved2 = std::max(moved2, (x - x_build[i]).squaredNorm());
          start_sums(i);
        }
      }
      // moved2 is complete after the loop's barrier; every thread reaches the same decision
      const bool rebuild_here =
          !have_build || neighbors_.needs_rebuild(moved2, walls_.planes(), meshes_);
      if (!rebuild_here) evaluate_forces(dt, true, half);
#pragma omp master
      rebuild = rebuild_here;
    }
    if (rebuild) {
      if (sort_interval_ > 0 && ++builds_since_sort_ >= sort_interval_) reorder_particles();
      rebuild_lists();
      compute_forces(dt, true, half, true);
    } else {
      reduce_wall_and_mesh_forces(dt, true);
    }
  }
  // the next step's bound starts from this one's (fused: the distances from the build positions
  // were not computed) or from the exact distances
  set_motion(fused ? bound : rebuild ? 0.0 : std::sqrt(moved2));
  for (TriangleMesh& m : meshes_)
    detail::parallel_pass(m.vertex_count(), [&](int v) { m.position_last_step_[v] = m.position_[v]; });
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].post_force(*this, dt);
  time_ += dt;
  ++steps_;
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].end_of_step(*this, dt);
  // a change of the particle set by a hook (breakage's fragments) is booked now, so that the
  // energies read after this step (a coupling window's audit) hold it; the next step's start
  // books what it still changes (System::settle_set_change())
  settle_set_change(true);
  if (profiling_) {
    const double wall = 1e-9 * static_cast<double>(now_ns() - profile_start);
    ++profile_.steps;
    profile_.step_s += wall;
    if (fused) ++profile_.fused_steps, profile_.fused_step_s += wall;
  }
}

void System::set_step_profiling(bool on) {
  profiling_ = on;
  if (on) profile_ = StepProfile{};
}

// After the join of a fused step's region: each team thread's marks into the profile.
void System::record_fused_pass(std::int64_t fork, std::int64_t join, int parts) {
  if (profile_.threads.size() < static_cast<std::size_t>(parts))
    profile_.threads.resize(static_cast<std::size_t>(parts));
  profile_.fused_region_s += 1e-9 * static_cast<double>(join - fork);
  std::int64_t last = fork;  // the slowest thread's end of its rows
  for (int t = 0; t < parts; ++t) {
    const ThreadMarks& m = marks_[t];
    if (m.enter == 0) continue;  // not in the team (fewer threads than parts)
    last = std::max(last, m.rows);
    StepProfile::Thread& p = profile_.threads[t];
    auto s = [](std::int64_t from, std::int64_t to) { return 1e-9 * static_cast<double>(to - from); };
    p.enter += s(fork, m.enter);
    p.drift += s(m.enter, m.drift);
    p.drift_wait += s(m.drift, m.drift_released);
    p.cross += s(m.drift_released, m.cross);
    p.cross_wait += s(m.cross, m.cross_released);
    p.rows += s(m.cross_released, m.rows);
    p.join_wait += s(m.rows, join);
  }
  profile_.fused_slowest_s += 1e-9 * static_cast<double>(last - fork);
}

void System::run(long steps, double dt) {
  for (long s = 0; s < steps; ++s) step(dt);
}

// ---- forces -----------------------------------------------------------------------------------

// Starts the force sums of a step in the packed state: F = m g, T = 0.
void System::start_sums(int i) {
  PackedParticle& q = verlet_.particle(i);
  q.f = store_.core().mass[i] * gravity_;
  q.t.setZero();
  if (track_load_) load_[i] = 0.0;
  if (energy_pass()) dissipation_[i].clear();
}

// Clears the per-part flags of the load limits, sizes the per-part motion maxima (no allocation
// once sized).
void System::start_load_pass(int parts) {
  load_reached_.assign(h_load_limit_ >= 0 ? static_cast<std::size_t>(parts) : 0, 0);
  part_motion_.resize(static_cast<std::size_t>(parts));
  if (profiling_ && marks_.size() < static_cast<std::size_t>(parts))
    marks_.resize(static_cast<std::size_t>(parts));
  // the force pass's per-part lists hold the listed pairs of one block of rows
  pair_scratch_.resize(static_cast<std::size_t>(parts));
  const std::vector<int>& offsets = neighbors_.offsets_;
  const int n = static_cast<int>(offsets.size()) - 1;
  int most = 0;
  for (int b = 0; b * block_size < n; ++b)
    most = std::max(most, offsets[std::min(n, (b + 1) * block_size)] - offsets[b * block_size]);
  const auto size = static_cast<std::size_t>(most);
  for (PairScratch& sc : pair_scratch_) {
    if (sc.tasks.size() >= size) continue;
    sc.tasks.resize(size + size / 4);  // (headroom: lists grow a little between builds)
    sc.forces.resize(size + size / 4);
    if (energy_pass()) sc.energy.resize(size + size / 4);
  }
  if (energy_terms_) particle_energy_.resize(store_.size());
  if (energy_pass()) {  // (no allocation while the sizes hold)
    for (PairScratch& sc : pair_scratch_)
      if (sc.energy.size() < sc.tasks.size()) sc.energy.resize(sc.tasks.size());
    dissipation_.resize(store_.size());
    block_energy_.resize((store_.size() + block_size - 1) / block_size);
    cross_energy_.resize(partition_.cross_pairs.size());
  }
}

// After a step's kick: the bound of the next step's motion (VelocityVerlet::Motion).
void System::set_motion(double moved) {
  VelocityVerlet::Motion mo;
  mo.moved = moved;
  double speed2 = 0.0, accel2 = 0.0;
  for (int t = 0; t < partition_.parts(); ++t) {
    speed2 = std::max(speed2, part_motion_[t].speed2);
    accel2 = std::max(accel2, part_motion_[t].accel2);
    mo.extent = std::max(mo.extent, part_motion_[t].extent);
  }
  mo.speed = std::sqrt(speed2);
  mo.accel = std::sqrt(accel2);
  if (std::isfinite(mo.moved + mo.speed + mo.accel + mo.extent))
    verlet_.set_motion(mo);
  else
    verlet_.forget_motion();  // (a diverging run: the next step takes the exact path)
}

void System::compute_forces(double dt, bool update_history, double kick, bool started) {
  if (!verlet_.loaded()) verlet_.load(store_.core());
  verlet_.moved();
  const int parts = set_partition();
  partition_.prepare_cross_pairs(neighbors_);
  start_load_pass(parts);
#pragma omp parallel if (parts > 1) num_threads(parts)
  {
    if (!started) {
#pragma omp for schedule(static, 1)
      for (int part = 0; part < parts; ++part)
        for (int i = partition_.begin(part); i < partition_.begin(part + 1); ++i) start_sums(i);
    }
    evaluate_forces(dt, update_history, kick);
  }
  reduce_wall_and_mesh_forces(dt, kick > 0.0 && update_history);
}

// Called inside a parallel region. Each particle's force is a sum in a fixed order, whatever the
// number of threads: F_i = m_i g (start_sums()) + the pairs (k, i), k < i, in ascending k + the
// pairs (i, j), j > i, in ascending j + planes + meshes. Rows are processed in ascending i, so the
// pairs (k, i) have all been added when row i starts and i's total is complete at the end of its
// row. Part t owns the particles [begin(t), begin(t+1)) of partition_ and adds pair forces to j
// directly when j is its own; pairs reaching into a later part (cross pairs) are evaluated first,
// each once, into its cross_force, then added by both owners in the same place of their sums.
void System::evaluate_forces(double dt, bool update_history, double kick, bool drift) {
  // the energies are those of a step (a kick and the histories' update)
  const bool energy = energy_pass() && kick > 0.0 && update_history;
  if (energy_terms_ && !energy)  // (a pass without a kick books nothing)
    std::fill(particle_energy_.begin(), particle_energy_.end(), ParticleEnergy{});
  auto run = [&]<bool Drift, bool Energy>() {
    if (track_load_)
      if (h_load_limit_ >= 0)
        evaluate_forces_impl<true, true, Drift, Energy>(dt, update_history, kick);
      else
        evaluate_forces_impl<true, false, Drift, Energy>(dt, update_history, kick);
    else
      evaluate_forces_impl<false, false, Drift, Energy>(dt, update_history, kick);
  };
  if (drift)
    if (energy)
      run.template operator()<true, true>();
    else
      run.template operator()<true, false>();
  else if (energy)
    run.template operator()<false, true>();
  else
    run.template operator()<false, false>();
}

template <bool Load, bool Limit, bool Drift, bool Energy>
void System::evaluate_forces_impl(double dt, bool update_history, double kick) {
  Particles& p = store_.core();
  const NeighborList& nl = neighbors_;
  ThreadPartition& tp = partition_;
  const int parts = tp.parts();
  const WallContacts::Pass walls = walls_.pass(store_);
  // Raw pointers, taken once: the loops keep them in registers (a vector's data pointer would be
  // reloaded after every store through the char touching flags, which may alias it).
  const VelocityVerlet::Pass verlet = verlet_.pass(p);
  const PairContacts::Pass pairs = pairs_.pass(p);
  PackedParticle* const packed = verlet.packed;
  const double* const mass = p.mass.data();
  const int* const material = p.material.data();
  double* load = Load ? load_.data() : nullptr;
  const double* load_limit = Limit ? store_.array<double>(h_load_limit_).data() : nullptr;
  const double* yield_pressure_of =
      yield_.pressure >= 0 ? store_.array<double>(yield_.pressure).data() : nullptr;
  // pairs with a yielding particle (nullptr: none)
  const PairYield pair_yield{yield_pressure_of, yield_.below_diameter, pairs.plastic};
  const PairYield* const yield = pairs.plastic != nullptr && yield_pressure_of != nullptr ? &pair_yield : nullptr;
  const MeshContacts::Pass mesh = mesh_contacts_.pass();  // rows: particles near a mesh
  const int* const offsets = nl.offsets_.data();
  const int* const neighbors = nl.neighbors_.data();
  const int np = walls.np;
  const PairBatchKernels& kernels = pair_batch_kernels();
  const PairBatchKernel batch = Energy ? (Load ? kernels.with_load_energy : kernels.plain_energy)
                                       : (Load ? kernels.with_load : kernels.plain);
  DissipationSums* const diss = Energy ? dissipation_.data() : nullptr;
  PairEnergy* const cross_energy = Energy ? cross_energy_.data() : nullptr;
  ParticleEnergy* const particle_energy = Energy && energy_terms_ ? particle_energy_.data() : nullptr;
  // Drift: the integrator's first half of particle i (with kick = dt/2) and the start of its
  // force sums, as the loop before the pass does it (step(), which knows that no particle can
  // have moved beyond the skin)
  const Eigen::Vector3d gravity = gravity_;
  // (a split bed's fused pass: particles whose first half was taken before it, or ghosts whose
  // values came from their owners, only start their sums)
  const char* const drifted = drift_skip_;
  auto drift = [&](int i) {
    if (drifted == nullptr || !drifted[i]) verlet.first_half(i, dt, kick);
    PackedParticle& q = packed[i];
    q.f = mass[i] * gravity;
    q.t.setZero();
    if constexpr (Load) load[i] = 0.0;
    if constexpr (Energy) diss[i].clear();
  };
  // step profile: this thread's clock at the phases (the barriers are explicit for that)
  ThreadMarks* const marks = profiling_ ? &marks_[thread_num()] : nullptr;
  if (marks) {
    const std::int64_t now = now_ns();
    *marks = ThreadMarks{now, now, now, now, now, now};
  }
  if constexpr (Drift) {
    if (parts > 1) {  // the particles that cross pairs read drift first
#pragma omp for schedule(static, 1) nowait
      for (int part = 0; part < parts; ++part) {
        for (int i = tp.begin(part); i < tp.drift_head_end[part]; ++i) drift(i);
        for (int i = tp.drift_tail_begin[part]; i < tp.begin(part + 1); ++i) drift(i);
      }
      if (marks) marks->drift = now_ns();
#pragma omp barrier
      if (marks) marks->drift_released = marks->cross = marks->cross_released = now_ns();
    }
  }
  if (parts > 1) {
    // The cross pairs, shared evenly among the threads in chunks, each chunk as a block of rows:
    // its touching pairs listed without a branch on the overlap test (a pair that parted has its
    // history settled), evaluated by the batched kernel, the results stored per pair. (With 16
    // parts of the 20,001-particle peer bed 17 % of the listed pairs cross; the scalar kernel
    // took them with its overlap branch, a coin flip for the predictor.)
    const int n_cross = static_cast<int>(tp.cross_pairs.size());
    const int chunks = (n_cross + cross_chunk - 1) / cross_chunk;
#pragma omp for schedule(static) nowait
    for (int ch = 0; ch < chunks; ++ch) {
      PairTask chunk_tasks[cross_chunk];
      PairForce chunk_forces[cross_chunk];
      PairEnergy chunk_energy[Energy ? cross_chunk : 1];
      const int k0 = ch * cross_chunk, k1 = std::min(n_cross, k0 + cross_chunk);
      int n_touch = 0;
      for (int k = k0; k < k1; ++k) {
        const ThreadPartition::CrossPair& c = tp.cross_pairs[k];
        const PackedParticle& qi = packed[c.i];
        const PackedParticle& qj = packed[c.j];
        const Eigen::Vector3d d = qi.x - qj.x;
        const double rsum = qi.r + qj.r;
        const bool touch = !(d.squaredNorm() >= rsum * rsum);  // (as the scalar kernel)
        if (static_cast<char>(touch) != pairs.touching[c.slot]) {
          pairs.touching[c.slot] = static_cast<char>(touch);
          if (!touch) {  // parted: the history is settled
            pairs.shear[c.slot].setZero();
            if (pairs.plastic != nullptr) pairs.plastic[c.slot] = 0.0f;
          }
        }
        tp.cross_force[k].touching = touch;
        chunk_tasks[n_touch] = PairTask{c.slot, c.i, c.j};
        n_touch += touch ? 1 : 0;
      }
      batch(chunk_tasks, n_touch, packed, mass, material, model_, pairs.shear, dt, update_history,
            chunk_forces, chunk_energy, yield);
      const PairForce* o = chunk_forces;
      for (int k = k0; k < k1; ++k) {
        ThreadPartition::CrossForce& cf = tp.cross_force[k];
        if (!cf.touching) continue;
        cf.force_i = Eigen::Vector3d(o->f[0], o->f[1], o->f[2]);
        cf.torque_i = Eigen::Vector3d(o->ti[0], o->ti[1], o->ti[2]);
        cf.torque_j = Eigen::Vector3d(o->tj[0], o->tj[1], o->tj[2]);
        if constexpr (Load) cf.load = o->load;
        if constexpr (Energy) cross_energy[k] = chunk_energy[o - chunk_forces];
        ++o;
      }
    }
    if (marks) marks->cross = now_ns();
#pragma omp barrier
    if (marks) marks->cross_released = now_ns();
  }
  // (no barrier at the end: the region's join follows in every caller)
#pragma omp for schedule(static, 1) nowait
  for (int part = 0; part < parts; ++part) {
    bool reached = false;  // a particle's load reached its limit (load_limit)
    // pairs (k, i) from earlier parts, ascending k
    for (int k = tp.cross_in_begin[part]; k < tp.cross_in_begin[part + 1]; ++k) {
      const int c = tp.cross_in[k];
      const ThreadPartition::CrossForce& cf = tp.cross_force[c];
      if (!cf.touching) continue;
      const int j = tp.cross_pairs[c].j;
      packed[j].f -= cf.force_i;
      packed[j].t += cf.torque_j;
      if constexpr (Load) load[j] = std::max(load[j], cf.load);
      if constexpr (Energy) {
        const PairEnergy& e = cross_energy[c];
        DissipationSums& dj = diss[j];
        dj.fd -= Eigen::Map<const Eigen::Vector3d>(e.fd);
        dj.td += Eigen::Map<const Eigen::Vector3d>(e.tdj);
        dj.ff -= Eigen::Map<const Eigen::Vector3d>(e.ff);
        dj.tf += Eigen::Map<const Eigen::Vector3d>(e.tfj);
      }
    }
    int cross = tp.cross_out_begin[part];
    const int lo = tp.begin(part), hi = tp.begin(part + 1);
    // Drift: particles [frontier, tail) have not drifted yet
    int frontier = hi, tail = hi;
    if constexpr (Drift) {
      frontier = parts > 1 ? tp.drift_head_end[part] : lo;
      tail = parts > 1 ? tp.drift_tail_begin[part] : hi;
    }
    double speed2 = 0.0, accel2 = 0.0, extent = 0.0;        // maxima after the kick
    int mesh_row = mesh.rows > 0 ? mesh.first_row(lo) : 0;  // the next particle near a mesh
    PairTask* const tasks = pair_scratch_[part].tasks.data();
    PairForce* const forces = pair_scratch_[part].forces.data();
    PairEnergy* const energies = Energy ? pair_scratch_[part].energy.data() : nullptr;
    int row_first[block_size + 1];  // where each row's touching pairs start in tasks
    int row_cross[block_size];      // each row's first cross pair (slot)
    for (int b = lo / block_size; b * block_size < hi; ++b) {
      // plane forces summed per block of particles, then over blocks (fixed order)
      Eigen::Vector3d* block_wall = walls.start_block(b);
      const int i_begin = b * block_size;
      const int i_end = std::min(hi, (b + 1) * block_size);
      // The block's touching pairs (pair_batch.hpp): listed without a branch on the overlap
      // test (a pair that parted has its history settled, zeroed, as PairContacts::force()
      // does), evaluated by the batched kernel, then added row by row in the order of the rows.
      // Cross pairs (j in a later part) come last in a row; their forces were evaluated before.
      int n_touch = 0;
      for (int i = i_begin; i < i_end; ++i) {
        if constexpr (Drift) {  // i and its row's neighbours in this part drift first (row by
          // row, so that their loads from memory overlap the rows' work)
          const int row_end = offsets[i + 1];
          const int need =
              row_end > offsets[i] ? std::max(i, std::min(neighbors[row_end - 1], hi - 1)) : i;
          for (; frontier <= need && frontier < tail; ++frontier) drift(frontier);
        }
        row_first[i - i_begin] = n_touch;
        const PackedParticle& qi = packed[i];
        int s = offsets[i];
        const int row_end = offsets[i + 1];
        for (; s < row_end; ++s) {
          const int j = neighbors[s];
          if (j >= hi) break;  // cross pairs (rows are sorted by j: the rest of the row)
          const PackedParticle& qj = packed[j];
          const Eigen::Vector3d d = qi.x - qj.x;
          const double rsum = qi.r + qj.r;
          const bool touch = !(d.squaredNorm() >= rsum * rsum);  // (as the scalar kernel)
          // the flag changes only where a contact starts or ends (rare: a predictable branch,
          // unlike one on the flag or on the test themselves)
          if (static_cast<char>(touch) != pairs.touching[s]) {
            pairs.touching[s] = static_cast<char>(touch);
            if (!touch) {  // parted: the history is settled
              pairs.shear[s].setZero();
              if (pairs.plastic != nullptr) pairs.plastic[s] = 0.0f;
            }
          }
          tasks[n_touch] = PairTask{s, i, j};
          n_touch += touch ? 1 : 0;
        }
        row_cross[i - i_begin] = s;
      }
      row_first[i_end - i_begin] = n_touch;
      batch(tasks, n_touch, packed, mass, material, model_, pairs.shear, dt, update_history,
            forces, energies, yield);
      BlockEnergy block_e;  // (Energy) this block's energies: powers x dt, spring energies
      for (int i = i_begin; i < i_end; ++i) {
        PackedParticle& qi = packed[i];
        Eigen::Vector3d f = qi.f;
        Eigen::Vector3d t = qi.t;
        double load_i = Load ? load[i] : 0.0;
        // (Energy) i's dissipative sums, held here for its row (the pairs (k, i), k < i, are in)
        DissipationSums di;
        if constexpr (Energy) di = diss[i];
        // (Energy) the per-contact terms of i's pairs (i, j): i's ParticleEnergy
        [[maybe_unused]] double row_spring = 0.0, row_stiffening = 0.0, row_plastic = 0.0;
        for (int k = row_first[i - i_begin]; k < row_first[i - i_begin + 1]; ++k) {
          const PairForce& o = forces[k];
          const Eigen::Map<const Eigen::Vector3d> fij(o.f), ti(o.ti), tj(o.tj);
          PackedParticle& qj = packed[tasks[k].j];
          f += fij;
          t += ti;
          qj.f -= fij;
          qj.t += tj;
          if constexpr (Load) {
            load_i = std::max(load_i, o.load);
            load[tasks[k].j] = std::max(load[tasks[k].j], o.load);
          }
          if constexpr (Energy) {
            const PairEnergy& e = energies[k];
            DissipationSums& dj = diss[tasks[k].j];
            const Eigen::Map<const Eigen::Vector3d> fd(e.fd), ff(e.ff);
            di.fd += fd;
            di.td += Eigen::Map<const Eigen::Vector3d>(e.tdi);
            di.ff += ff;
            di.tf += Eigen::Map<const Eigen::Vector3d>(e.tfi);
            dj.fd -= fd;
            dj.td += Eigen::Map<const Eigen::Vector3d>(e.tdj);
            dj.ff -= ff;
            dj.tf += Eigen::Map<const Eigen::Vector3d>(e.tfj);
            block_e.friction += e.spring;
            block_e.stiffening += e.stiffening;
            block_e.damping += e.plastic;
            row_spring += e.spring;
            row_stiffening += e.stiffening;
            row_plastic += e.plastic;
          }
        }
        for (int s = row_cross[i - i_begin]; s < offsets[i + 1]; ++s) {  // already evaluated
          const int c = cross++;
          const ThreadPartition::CrossForce& cf = tp.cross_force[c];
          if (cf.touching) {
            f += cf.force_i, t += cf.torque_i;
            if constexpr (Load) load_i = std::max(load_i, cf.load);
            if constexpr (Energy) {
              const PairEnergy& e = cross_energy[c];
              di.fd += Eigen::Map<const Eigen::Vector3d>(e.fd);
              di.td += Eigen::Map<const Eigen::Vector3d>(e.tdi);
              di.ff += Eigen::Map<const Eigen::Vector3d>(e.ff);
              di.tf += Eigen::Map<const Eigen::Vector3d>(e.tfi);
              block_e.friction += e.spring;
              block_e.stiffening += e.stiffening;
              block_e.damping += e.plastic;
              row_spring += e.spring;
              row_stiffening += e.stiffening;
              row_plastic += e.plastic;
            }
          }
        }
        WallDissipation wd;  // (Energy) i's wall and mesh contacts
        walls.add_forces<Load, Energy>(i, qi, mass[i], material[i],
                                       np <= 64 ? nl.plane_mask_[i] : 0, model_, dt,
                                       update_history, f, t, load_i, block_wall, &di, &wd);
        if (mesh_row < mesh.rows && mesh.particle[mesh_row] == i) {
          // own accumulators: f and t keep their registers
          Eigen::Vector3d fm = Eigen::Vector3d::Zero(), tm = Eigen::Vector3d::Zero();
          const double yield_pressure =
              yield_pressure_of != nullptr && 2.0 * qi.r < yield_.below_diameter ? yield_pressure_of[i] : 0.0;
          const MeshContacts::Particle q{qi.x,      qi.r,        qi.v,          mass[i],
                                         qi.w,      material[i], yield_pressure, steps_ == 0};
          MeshContacts::evaluate<Load, Energy>(i, q, nl, meshes_, model_, mesh.row(mesh_row++),
                                               dt, update_history, fm, tm, load_i, &di, &wd);
          f += fm;
          t += tm;
        }
        qi.f = f;
        qi.t = t;
        if constexpr (Load) {  // (i's load is complete: the pairs (k, i), k < i, came first)
          load[i] = load_i;
          if constexpr (Limit) reached |= load_i >= load_limit[i];
        }
        // the integrator's closing kick (no other row reads particle i any more in this pass)
        if (kick > 0.0) {
          verlet.kick(i, kick, f, t);
          speed2 = std::max(speed2, qi.v.squaredNorm());
          accel2 = std::max(accel2, f.squaredNorm() / (mass[i] * mass[i]));
          extent = std::max(extent, qi.x.cwiseAbs().maxCoeff());
          if constexpr (Energy) {  // powers at the end-of-step velocities (Energies)
            const double damping =
                (wd.damping - (di.fd.dot(qi.v) + di.td.dot(qi.w))) * dt + wd.plastic;
            const double friction =
                (wd.friction - (di.ff.dot(qi.v) + di.tf.dot(qi.w))) * dt + wd.spring;
            const double gravity_work = mass[i] * gravity.dot(qi.v) * dt;
            block_e.damping += damping;
            block_e.friction += friction;
            block_e.gravity += gravity_work;
            block_e.stiffening += wd.stiffening;
            if (particle_energy != nullptr)
              particle_energy[i] = ParticleEnergy{row_plastic + damping, row_spring + friction,
                                                  gravity_work, row_stiffening + wd.stiffening};
          }
        }
      }
      if constexpr (Energy) block_energy_[b] = block_e;
    }
    if (reached) load_reached_[part] = 1;
    part_motion_[part] = {speed2, accel2, extent};
  }
  if (marks) marks->rows = now_ns();
}

void System::reduce_wall_and_mesh_forces(double dt, bool work) {
  const int n = static_cast<int>(store_.size());
  walls_.reduce(n);
  work = work && energy_tracking_;
  if (work) {  // the step's energies: block sums in order, the walls' and meshes' work
    Energies& e = energies_;
    for (const BlockEnergy& b : block_energy_) {
      e.damping += b.damping;
      e.friction += b.friction;
      e.gravity += b.gravity;
      e.stiffening += b.stiffening;
    }
    walls_.add_work(dt, e.wall_work);
    // each contact's force on its particle times the mesh's velocity at the contact point
    // (barycentric), particles in order
    mesh_contacts_.for_each_contact([&](int, const MeshContactRecord& rec, const Eigen::Vector3d&) {
      const Eigen::Vector3d v_wall =
          meshes_[rec.mesh].velocity_at(rec.triangle, rec.barycentric);
      e.mesh_work[static_cast<std::size_t>(rec.mesh)] += rec.force.dot(v_wall) * dt;
    });
  }
  // Mesh forces: particles in order (MeshContacts::reduce).
  if (meshes_.empty()) return;
  mesh_contacts_.reduce(meshes_);
  for (TriangleMesh& m : meshes_) m.clear_fresh();
}

}  // namespace partita::dem
