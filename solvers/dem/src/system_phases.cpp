// System: a step cut into phases, for a bed split into subdomains (subdomain.hpp drives them).
//
// The phases are step()'s operations in the same order, where the subdomains of a split bed
// exchange data between them (system.hpp's "a step in phases" lists them):
//   phase_begin     walls_.advance(), the meshes' velocities from their motion, the checks
//   phase_drift     (the exact path) the first half and the start of the force sums, particle
//                   by particle; the caller makes the rebuild decision for all subdomains at
//                   once and sends ghosts' values from their owners, or at a build the particles
//                   that move between subdomains
//   phase_build     the lists (rebuild_lists(), with the pair histories received placed)
//   phase_forces    compute_forces() with the kick
//   phase_fusable, phase_drift_some, phase_forces_fused
//                   (the fused path, where the motion bound of the last step rules out a build on
//                   every subdomain) the first half of the particles others read as ghosts, then
//                   the force pass with every other particle's first half inside it, as step()
//   phase_finish    what step() does after its force pass
// A System without particles (a split bed's empty subdomain) takes phase_begin() (the walls' and
// meshes' motion only) and phase_finish(): its walls and meshes are where every other
// subdomain's are when particles arrive.
// What differs from step(): the rebuild decision and the choice of the fused path are the
// caller's (over the split), and the lists are renumbered by the caller (its global order)
// instead of by set_sort_interval().
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/exact_sum.hpp"
#include "motion_bound.hpp"
#include "parallel_pass.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace partita::dem {

void System::phase_begin(double dt) {
  if (energy_tracking_)
    throw Error(
        "phase_begin: the energy accounting is not available in a step taken in phases (a split "
        "bed); turn it off (set_energy_tracking(false))");
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "phase_begin: the time step must be > 0 s, got " << dt;
    throw Error(msg.str());
  }
  // the meshes' velocities from their motion since the last step (where the caller gave none)
  // and the walls' positions after this step
  const auto move_walls_and_meshes = [&] {
    for (TriangleMesh& m : meshes_) {
      if (!m.velocity_from_motion_) continue;
      detail::parallel_pass(m.vertex_count(), [&](int v) {
        m.velocity_[v] = (m.position_[v] - m.position_last_step_[v]) / dt;
      });
    }
    walls_.advance(dt);
  };
  if (store_.size() == 0) {  // an empty subdomain: its walls and meshes move all the same
    move_walls_and_meshes();
    phase_begun_ = true;
    return;
  }
  prepare();
  constexpr double kStepTolerance = 1e-9;  // (as step())
  if (dt > rayleigh_dt_ * (1.0 + kStepTolerance)) {
    std::ostringstream msg;
    msg.precision(6);
    msg << "phase_begin: time step " << dt << " s is above the Rayleigh time step " << rayleigh_dt_
        << " s of the smallest particle; use a fraction of it (rayleigh_time_step())";
    throw Error(msg.str());
  }
  if (!forces_valid_)
    throw Error(
        "phase_begin: the particles have no forces of a force pass yet; call "
        "phase_forces(dt, false) after the first phase_build()");
  if (!verlet_.loaded()) verlet_.load(store_.core());
  verlet_.moved();
  move_walls_and_meshes();
  // (the sums start in the first half; a System resumed from a restart has had no force pass to
  // size them)
  if (energy_pass() && dissipation_.size() != store_.size()) dissipation_.resize(store_.size());
  phase_begun_ = true;
}

double System::phase_drift(double dt, const std::vector<char>& skip) {
  if (!phase_begun_) throw Error("phase_drift: take phase_begin(dt) first");
  phase_begun_ = false;
  if (store_.size() == 0) return 0.0;
  const std::size_t n = store_.size();
  if (!skip.empty() && skip.size() != n)
    throw Error("phase_drift: need one skip flag per particle (" + std::to_string(n) + "), got " +
                std::to_string(skip.size()));
  const VelocityVerlet::Pass verlet = verlet_.pass(store_.core());
  const std::vector<Eigen::Vector3d>& x_build = neighbors_.position_at_build_;
  const bool have_build = x_build.size() == n;
  const double half = 0.5 * dt;
  double moved2 = have_build ? 0.0 : std::numeric_limits<double>::infinity();
  const long count = static_cast<long>(n);
#pragma omp parallel for schedule(static) reduction(max : moved2) if (count >= 1024)
  for (long k = 0; k < count; ++k) {
    const int i = static_cast<int>(k);
    const Eigen::Vector3d& x = verlet.first_half(i, dt, half);
    if (have_build && (skip.empty() || !skip[k]))
      moved2 = std::max(moved2, (x - x_build[k]).squaredNorm());
    start_sums(i);
  }
  phase_sums_started_ = true;  // (phase_forces() need not start them again)
  return moved2;
}

bool System::phase_fusable(double dt, double& bound) const {
  bound = 0.0;
  if (store_.size() == 0) return true;  // (nothing to bound: the other subdomains decide)
  if (!verlet_.has_motion() || !verlet_.loaded() ||
      neighbors_.position_at_build_.size() != store_.size())
    return false;
  bound = detail::motion_bound(verlet_.motion(), dt);  // (as step())
  return !neighbors_.needs_rebuild(bound * bound, walls_.planes(), meshes_);
}

void System::phase_drift_some(double dt, const std::vector<int>& particles) {
  if (!phase_begun_) throw Error("phase_drift_some: take phase_begin(dt) first");
  phase_begun_ = false;
  if (store_.size() == 0) return;
  const VelocityVerlet::Pass verlet = verlet_.pass(store_.core());
  const double half = 0.5 * dt;
  const long count = static_cast<long>(particles.size());
  const long n = static_cast<long>(store_.size());
  for (const int i : particles)
    if (i < 0 || i >= n)
      throw Error("phase_drift_some: particle " + std::to_string(i) + " of " +
                  std::to_string(n));
#pragma omp parallel for schedule(static) if (count >= 1024)
  for (long k = 0; k < count; ++k) verlet.first_half(particles[static_cast<std::size_t>(k)], dt, half);
}

bool System::phase_needs_rebuild(double moved2) const {
  return neighbors_.needs_rebuild(moved2, walls_.planes(), meshes_);
}

void System::phase_motion(std::size_t i, Eigen::Vector3d& x, Eigen::Vector3d& v,
                          Eigen::Vector3d& w) const {
  check_particle(i, "phase_motion");
  if (verlet_.loaded()) {
    const PackedParticle& q = verlet_.particle(i);
    x = q.x, v = q.v, w = q.w;
  } else {
    const Particles& p = store_.core();
    x = p.position[i], v = p.velocity[i], w = p.angular_velocity[i];
  }
}

void System::set_phase_motion(std::size_t i, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                              const Eigen::Vector3d& w) {
  check_particle(i, "set_phase_motion");
  if (!verlet_.loaded())
    throw Error("set_phase_motion: only between phase_drift() and phase_forces()");
  PackedParticle& q = verlet_.particle(i);
  q.x = x, q.v = v, q.w = w;
}

void System::phase_build(const std::vector<char>* passive) {
  if (sort_interval_ > 0)
    throw Error(
        "phase_build: the particles of a step taken in phases are numbered by the caller; set "
        "set_sort_interval(0)");
  prepared_ = false;
  lists_current_ = false;
  phase_sums_started_ = false;
  neighbors_.set_passive(passive);
  try {
    prepare();  // (rayleigh_dt_, history sizes, the lists)
  } catch (...) {
    neighbors_.set_passive(nullptr);
    throw;
  }
  neighbors_.set_passive(nullptr);  // (a later build of its own lists every pair)
}

void System::phase_forces(double dt, bool step) {
  // The sums started by this step's phase_drift() hold where nothing changed since (no build, no
  // change of the particles: prepared, the packed state still loaded): a refresh of the ghosts'
  // values sets their motion only. Not starting them again saves a pass over the particles and
  // gives the same bits (start_sums() writes the same values).
  const bool started = phase_sums_started_ && prepared_ && verlet_.loaded();
  phase_sums_started_ = false;
  prepare();
  compute_forces(dt, step, step ? 0.5 * dt : 0.0, started);
  forces_valid_ = true;
}

void System::phase_forces_fused(double dt, const std::vector<char>& drifted) {
  if (drifted.size() != store_.size())
    throw Error("phase_forces_fused: need one flag per particle (" +
                std::to_string(store_.size()) + "), got " + std::to_string(drifted.size()));
  if (store_.size() == 0) return;
  phase_sums_started_ = false;
  prepare();  // (the lists are current: nothing to do)
  const int parts = set_partition();
  partition_.prepare_cross_pairs(neighbors_);
  start_load_pass(parts);
  const double half = 0.5 * dt;
  drift_skip_ = drifted.data();
  try {
#pragma omp parallel if (parts > 1) num_threads(parts)
    evaluate_forces(dt, true, half, true);
  } catch (...) {
    drift_skip_ = nullptr;
    throw;
  }
  drift_skip_ = nullptr;
  reduce_wall_and_mesh_forces(dt, true);
  forces_valid_ = true;
}

void System::phase_finish(double dt, double moved) {
  phase_begun_ = false;
  // the bound of the next step's motion where the caller keeps it (phase_fusable()), else a
  // later step takes the exact path
  if (moved >= 0.0 && store_.size() > 0 && verlet_.loaded())
    set_motion(moved);
  else
    verlet_.forget_motion();
  for (TriangleMesh& m : meshes_)
    detail::parallel_pass(m.vertex_count(),
                          [&](int v) { m.position_last_step_[v] = m.position_[v]; });
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].post_force(*this, dt);
  time_ += dt;
  ++steps_;
  // (a hook that replaces particles is driven by the split's stepper: step_hook.hpp)
  for (int k = 0; k < hooks_.size(); ++k)
    if (!hooks_[k].replaces_particles()) hooks_[k].end_of_step(*this, dt);
}

void System::add_elastic_energy(const std::vector<char>& skip, ExactSum& sum) const {
  sync_particles();
  const Particles& p = store_.core();
  const NeighborList& nl = neighbors_;
  if (!lists_current_ || nl.offsets_.size() != p.size() + 1 ||
      pairs_.slot_count() != nl.neighbors_.size() || skip.size() != p.size())
    throw Error(
        "add_elastic_energy: needs the lists of the current particles (take a step after a "
        "change of the particle set) and one flag per particle (" +
        std::to_string(p.size()) + "), got " + std::to_string(skip.size()));
  const_cast<ContactModel&>(model_).update();
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i) {  // (the terms as elastic_energy() takes them)
    if (skip[i]) continue;
    for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
      const int j = nl.neighbors_[s];
      const double rsum = p.radius[i] + p.radius[j];
      const double delta = rsum - (p.position[i] - p.position[j]).norm();
      if (delta <= 0.0) continue;
      sum.add(hertz_elastic_energy(model_.pair(p.material[i], p.material[j]),
                                   elastic_overlap(delta, pairs_.plastic(s)),
                                   p.radius[i] * p.radius[j] / rsum, pairs_.shear(s)));
    }
  }
  const std::vector<Eigen::Vector3d>& plane_shear = walls_.shear(store_);
  const std::vector<PlaneWall>& planes = walls_.planes();
  const std::size_t np = planes.size();
  const bool have_shear = plane_shear.size() == p.size() * np;
  const Eigen::Vector3d no_shear = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (skip[i]) continue;
    for (std::size_t k = 0; k < np; ++k) {
      const double delta = p.radius[i] - (p.position[i] - planes[k].point).dot(planes[k].normal);
      if (delta <= 0.0) continue;
      sum.add(hertz_elastic_energy(model_.pair(p.material[i], planes[k].material), delta,
                                   p.radius[i], have_shear ? plane_shear[i * np + k] : no_shear));
    }
  }
  mesh_contacts_.for_each_contact(
      [&](int i, const MeshContactRecord& rec, const Eigen::Vector3d& shear) {
        if (skip[i]) return;
        sum.add(hertz_elastic_energy(model_.pair(p.material[i], rec.material), rec.delta,
                                     rec.r_eff, shear));
      });
}

void System::add_half_step_term(const std::vector<char>& skip, double dt, ExactSum& sum) const {
  sync_particles();
  const Particles& p = store_.core();
  const std::size_t n = p.size();
  const std::vector<PlaneWall>& planes = walls_.planes();
  if (skip.size() != n)
    throw Error("add_half_step_term: needs one flag per particle (" + std::to_string(n) +
                "), got " + std::to_string(skip.size()));
  if (n > 0 && !planes.empty() && !wall_reactions_recorded())
    throw Error(
        "add_half_step_term: the planes' reactions are not recorded (set_wall_reactions(true) "
        "before the force pass)");
  const double h = 0.5 * dt, h2 = 0.125 * dt * dt;
  for (std::size_t i = 0; i < n; ++i) {  // (the terms as half_step_term() takes them)
    if (skip[i]) continue;
    const Eigen::Vector3d &f = p.force[i], &t = p.torque[i];
    sum.add(h * (f.dot(p.velocity[i]) + t.dot(p.angular_velocity[i])) +
            h2 * (f.squaredNorm() / p.mass[i] + t.squaredNorm() / p.inertia[i]));
    for_each_wall_reaction(i, [&](std::size_t k, const Eigen::Vector3d& r) {
      if (planes[k].velocity != Eigen::Vector3d::Zero())  // the planes' motion: -F . v over dt/2
        sum.add(-h * r.dot(planes[k].velocity));
    });
  }
  mesh_contacts_.for_each_contact([&](int i, const MeshContactRecord& rec, const Eigen::Vector3d&) {
    if (skip[i]) return;
    sum.add(h * rec.force.dot(meshes_[rec.mesh].velocity_at(rec.triangle, rec.barycentric)));
  });
}

}  // namespace partita::dem
