// System: set-up, particle set changes, hooks and access. The step and the force pass are in
// system_step.cpp, the state in system_state.cpp, monitors and output in system_monitors.cpp.
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/restitution_calibration.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace partita::dem {

namespace {

std::uint64_t new_identity() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

System::System() : identity_(new_identity()) {
  neighbors_.clear();
  walls_.attach(store_);
}

// ---- set-up ---------------------------------------------------------------------------------

int System::add_material(const Material& material) {
  prepared_ = false;
  return model_.add_material(material);
}

void System::add_interaction(int a, int b, const Interaction& interaction) {
  model_.set_interaction(a, b, interaction);
  prepared_ = false;
}

void System::set_damping_model(DampingModel model) {
  model_.set_damping_model(model);
  prepared_ = false;
}

void System::set_skin(double skin) {
  if (!(skin >= 0.0) || !std::isfinite(skin)) {
    std::ostringstream msg;
    msg << "set_skin: the Verlet skin must be a finite length >= 0 m, got " << skin;
    throw Error(msg.str());
  }
  skin_ = skin;
  prepared_ = false;
  lists_current_ = false;
}

// The particle set changed: the next step prepares again (time step, lists). The forces of the
// other particles stay those of the last pass (as in LAMMPS, a particle added or removed between
// steps acts on the others from the next force pass on).
void System::particles_changed() {
  prepared_ = false;
  lists_current_ = false;
  verlet_.invalidate();
  partition_.invalidate();
}

std::size_t System::add_particle(const Eigen::Vector3d& x, double radius, int material,
                                 const Eigen::Vector3d& v, const Eigen::Vector3d& w,
                                 std::int64_t id) {
  sync_particles();
  note_set_change();
  const std::size_t index = store_.size();
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    std::ostringstream msg;
    msg << "add_particle " << index << ": radius must be a finite length > 0 m, got " << radius;
    throw Error(msg.str());
  }
  if (!x.allFinite() || !v.allFinite() || !w.allFinite()) {
    std::ostringstream msg;
    msg << "add_particle " << index << ": position " << vector_text(x) << ", velocity " << vector_text(v)
        << " and angular velocity " << vector_text(w) << " must be finite";
    throw Error(msg.str());
  }
  model_.check_material(material, "add_particle " + std::to_string(index));
  const double rho = model_.material(material).density;
  const double m = rho * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  store_.add(id);
  Particles& p = store_.core();
  p.position[index] = x;
  p.velocity[index] = v;
  p.angular_velocity[index] = w;
  p.radius[index] = radius;
  p.mass[index] = m;
  p.inertia[index] = 0.4 * m * radius * radius;
  p.material[index] = material;
  p.force[index] = m * gravity_;  // until the next force pass: its weight
  particles_changed();
  return index;
}

std::size_t System::add_particles(const Eigen::Ref<const Eigen::MatrixX3d>& positions,
                                  const Eigen::Ref<const Eigen::VectorXd>& radii, int material) {
  if (positions.rows() != radii.size()) {
    std::ostringstream msg;
    msg << "add_particles: " << positions.rows() << " positions but " << radii.size()
        << " radii; give one radius per position";
    throw Error(msg.str());
  }
  const std::size_t first = store_.size();
  store_.reserve(first + positions.rows());
  for (Eigen::Index k = 0; k < positions.rows(); ++k)
    add_particle(positions.row(k).transpose(), radii[k], material);
  return first;
}

void System::check_particle(std::size_t i, const char* what) const {
  if (i >= store_.size()) {
    std::ostringstream msg;
    msg << what << ": no particle " << i << "; there are " << store_.size();
    throw Error(msg.str());
  }
}

void System::set_particle_velocity(std::size_t i, const Eigen::Vector3d& v,
                                   const Eigen::Vector3d& w) {
  check_particle(i, "set_particle_velocity");
  sync_particles();
  note_set_change();
  store_.core().velocity[i] = v;
  store_.core().angular_velocity[i] = w;
  forces_valid_ = false;
  verlet_.invalidate();
}

void System::set_particle_mass(std::size_t i, double mass, double inertia) {
  check_particle(i, "set_particle_mass");
  if (!(mass > 0.0) || !(inertia > 0.0) || !std::isfinite(mass) || !std::isfinite(inertia)) {
    std::ostringstream msg;
    msg << "set_particle_mass " << i << ": mass and moment of inertia must be finite and > 0, got "
        << mass << " kg and " << inertia << " kg m^2";
    throw Error(msg.str());
  }
  sync_particles();
  note_set_change();
  store_.core().mass[i] = mass;
  store_.core().inertia[i] = inertia;
  forces_valid_ = false;
  verlet_.invalidate();
}

void System::remove_particles(const std::vector<char>& remove) {
  sync_particles();
  if (remove.size() != store_.size()) {
    std::ostringstream msg;
    msg << "remove_particles: need one flag per particle (" << store_.size() << "), got "
        << remove.size();
    throw Error(msg.str());
  }
  if (std::none_of(remove.begin(), remove.end(), [](char c) { return c != 0; })) return;
  note_set_change();
  store_.remove(remove, new_of_old_);
  // pair and mesh histories follow their particles; the lists are rebuilt before the next use
  neighbors_.renumber(new_of_old_, static_cast<int>(store_.size()));
  pairs_follow_lists();
  mesh_contacts_.renumber(new_of_old_);
  particles_changed();
}

void System::shrink_to_fit() {
  sync_particles();
  store_.shrink_to_fit();
  new_of_old_.clear();
  new_of_old_.shrink_to_fit();
}

std::size_t System::replace_particles(const std::vector<char>& remove,
                                      const std::vector<Fragment>& fragments) {
  sync_particles();
  const std::size_t n = store_.size();
  if (remove.size() != n) {
    std::ostringstream msg;
    msg << "replace_particles: need one flag per particle (" << n << "), got " << remove.size();
    throw Error(msg.str());
  }
  const Particles& p = store_.core();
  bool inside = true;  // every fragment's sphere within its parent's
  for (std::size_t k = 0; k < fragments.size(); ++k) {
    const Fragment& f = fragments[k];
    if (f.parent >= n || !remove[f.parent]) {
      std::ostringstream msg;
      msg << "replace_particles: fragment " << k << " names parent " << f.parent
          << ", which is not a particle removed in the same change";
      throw Error(msg.str());
    }
    inside = inside && (f.position - p.position[f.parent]).norm() + f.radius <= p.radius[f.parent];
  }
  const bool local = local_fragments_ && inside && lists_current_ && neighbors_.built() &&
                     neighbors_.position_at_build_.size() == n;
  if (!local) {
    remove_particles(remove);
    std::size_t first = store_.size();
    for (std::size_t k = 0; k < fragments.size(); ++k) {
      const Fragment& f = fragments[k];
      const std::size_t i =
          add_particle(f.position, f.radius, f.material, f.velocity, f.angular_velocity, f.id);
      if (k == 0) first = i;
      if (f.mass > 0.0) set_particle_mass(i, f.mass, f.inertia);
    }
    return first;
  }
  // Check every fragment before the set changes (the system stays as it was on an error).
  for (std::size_t k = 0; k < fragments.size(); ++k) {
    const Fragment& f = fragments[k];
    const std::string what = "replace_particles: fragment " + std::to_string(k);
    if (!(f.radius > 0.0) || !std::isfinite(f.radius) || !f.position.allFinite() ||
        !f.velocity.allFinite() || !f.angular_velocity.allFinite() ||
        (f.mass > 0.0 && !(std::isfinite(f.mass) && f.inertia > 0.0 && std::isfinite(f.inertia)))) {
      std::ostringstream msg;
      msg << what << ": radius, position, velocities, mass and moment of inertia must be finite, "
          << "radius > 0 m and (with a mass) mass and moment of inertia > 0";
      throw Error(msg.str());
    }
    model_.check_material(f.material, what);
  }
  // The energy the change takes out of KE + E_el is booked here from the particles it
  // touches (the whole bed's sums before and after differ by just that), unless an earlier change
  // since the last step is pending (then the step's end books both over the whole bed).
  const bool book = energy_tracking_ && energies_.started && !set_change_pending_;
  double before = 0.0;
  if (book) {
    set_members_.assign(n, 0);
    set_which_.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (remove[i]) set_members_[i] = 1, set_which_.push_back(i);
    before = set_energy(set_which_, set_members_);
  } else {
    note_set_change();
  }
  offspring_.resize(fragments.size());
  // (the parents' values are read before the store moves its rows)
  std::vector<ParentShare>& share = share_;
  share.resize(fragments.size());
  for (std::size_t k = 0; k < fragments.size(); ++k) {
    const Fragment& f = fragments[k];
    const std::size_t q = f.parent;
    offspring_[k] = {static_cast<int>(q), f.position - p.position[q]};
    share[k] = {p.force[q], p.torque[q], p.mass[q], p.inertia[q]};
  }
  store_.remove(remove, new_of_old_);
  const int kept = static_cast<int>(store_.size());
  for (std::size_t k = 0; k < fragments.size(); ++k) {
    const Fragment& f = fragments[k];
    const std::size_t i = store_.add(f.id);
    Particles& c = store_.core();
    const double rho = model_.material(f.material).density;
    const double m = f.mass > 0.0 ? f.mass : rho * 4.0 / 3.0 * std::numbers::pi * f.radius * f.radius * f.radius;
    const double inertia = f.mass > 0.0 ? f.inertia : 0.4 * m * f.radius * f.radius;
    c.position[i] = f.position;
    c.velocity[i] = f.velocity;
    c.angular_velocity[i] = f.angular_velocity;
    c.radius[i] = f.radius;
    c.mass[i] = m;
    c.inertia[i] = inertia;
    c.material[i] = f.material;
    c.force[i] = m / share[k].mass * share[k].force;
    c.torque[i] = inertia / share[k].inertia * share[k].torque;
  }
  neighbors_.insert_offspring(new_of_old_, kept, offspring_, store_.core());
  pairs_follow_lists();
  mesh_contacts_.renumber(new_of_old_);
  mesh_contacts_.follow_build(neighbors_);
  // the step prepares again (time step, histories' sizes) with the lists as they are
  prepared_ = false;
  verlet_.invalidate();
  partition_.invalidate();
  ++local_insertions_;
  if (book) {
    const std::size_t n_after = store_.size();
    resize_histories();  // (the planes' histories of the fragments: none yet)
    set_members_.assign(n_after, 0);
    set_which_.clear();
    for (std::size_t i = static_cast<std::size_t>(kept); i < n_after; ++i)
      set_members_[i] = 1, set_which_.push_back(i);
    energies_.breakage += before - set_energy(set_which_, set_members_);
  }
  return static_cast<std::size_t>(kept);
}

void System::renumber_particles(const std::vector<int>& order) {
  sync_particles();
  const std::size_t n = store_.size();
  bool ok = order.size() == n;
  new_of_old_.assign(n, -1);
  for (std::size_t k = 0; ok && k < n; ++k) {
    ok = order[k] >= 0 && static_cast<std::size_t>(order[k]) < n && new_of_old_[order[k]] < 0;
    if (ok) new_of_old_[order[k]] = static_cast<int>(k);
  }
  if (!ok) {
    std::ostringstream msg;
    msg << "renumber_particles: need a permutation of 0.." << n - 1 << " (" << n
        << " distinct indices), got " << order.size() << " entries that are not one";
    throw Error(msg.str());
  }
  store_.permute(order);
  neighbors_.renumber(new_of_old_);
  pairs_follow_lists();
  mesh_contacts_.renumber(new_of_old_);
  verlet_.invalidate();
  partition_.invalidate();
  prepared_ = false;
  lists_current_ = false;
}

int System::add_hook(std::unique_ptr<StepHook> hook) {
  if (!hook) throw Error("add_hook: no hook given");
  const int k = hooks_.add(std::move(hook));
  hooks_[k].attach(*this);
  track_load_ = track_load_ || hooks_[k].wants_contact_load();
  if (const int h = hooks_[k].contact_load_limit(); h >= 0) {
    if (h_load_limit_ >= 0)
      throw Error("add_hook: '" + hooks_[k].name() +
                  "' brings contact load limits and another hook has them already (one per "
                  "system)");
    h_load_limit_ = h;
  }
  if (const StepHook::ContactYield y = hooks_[k].contact_yield(); y.pressure >= 0) {
    if (yield_.pressure >= 0)
      throw Error("add_hook: '" + hooks_[k].name() +
                  "' brings contact yield pressures and another hook has them already (one per "
                  "system)");
    yield_ = y;
    pairs_.keep_plastic();  // pairs with a yielding particle keep their permanent overlaps
  }
  forces_valid_ = false;
  prepared_ = false;  // sizes the load array (the lists stay)
  return k;
}

int System::add_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int material,
                      const Eigen::Vector3d& velocity) {
  model_.check_material(material, "add_plane");
  const int wall = walls_.add_plane(point, normal, material, velocity);
  prepared_ = false;
  lists_current_ = false;
  forces_valid_ = false;
  return wall;
}

int System::add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material,
                    unsigned faces) {
  model_.check_material(material, "add_box");
  const int wall = walls_.add_box(lo, hi, material, faces);
  prepared_ = false;
  lists_current_ = false;
  forces_valid_ = false;
  return wall;
}

void System::set_wall_velocity(int wall, const Eigen::Vector3d& velocity) {
  walls_.set_velocity(wall, velocity);
}

int System::add_mesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices,
                     const TriangleMesh::Triangles& triangles, int material) {
  model_.check_material(material, "add_mesh");
  meshes_.emplace_back(vertices, triangles, material);
  prepared_ = false;
  lists_current_ = false;
  forces_valid_ = false;
  return static_cast<int>(meshes_.size()) - 1;
}

void System::check_mesh(int mesh, const char* what) const {
  if (mesh < 0 || mesh >= mesh_count()) {
    std::ostringstream msg;
    msg << what << ": unknown mesh id " << mesh;
    if (mesh_count() == 0)
      msg << "; no mesh added";
    else
      msg << "; ids are 0.." << mesh_count() - 1;
    throw Error(msg.str());
  }
}

const TriangleMesh& System::mesh(int mesh) const {
  check_mesh(mesh, "mesh");
  return meshes_[mesh];
}

void System::set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& x) {
  check_mesh(mesh, "set_vertex_positions");
  TriangleMesh& m = meshes_[mesh];
  if (x.rows() != m.vertex_count()) {
    std::ostringstream msg;
    msg << "set_vertex_positions: mesh " << mesh << " has " << m.vertex_count() << " vertices, got "
        << x.rows() << " rows";
    throw Error(msg.str());
  }
  if (!x.allFinite()) throw Error("set_vertex_positions: non-finite coordinate");
  for (int v = 0; v < m.vertex_count(); ++v) m.position_[v] = x.row(v).transpose();
  m.velocity_from_motion_ = true;
}

void System::set_vertex_positions(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& x,
                                  const Eigen::Ref<const Eigen::MatrixX3d>& v) {
  set_vertex_positions(mesh, x);
  set_vertex_velocities(mesh, v);
}

void System::set_mesh_one_sided(int mesh, bool one_sided) {
  check_mesh(mesh, "set_mesh_one_sided");
  meshes_[mesh].set_one_sided(one_sided);
  forces_valid_ = false;
}

void System::set_triangle_active(int mesh, int triangle, bool active) {
  check_mesh(mesh, "set_triangle_active");
  meshes_[mesh].set_triangle_active(triangle, active);
}

void System::set_vertex_velocities(int mesh, const Eigen::Ref<const Eigen::MatrixX3d>& v) {
  check_mesh(mesh, "set_vertex_velocities");
  TriangleMesh& m = meshes_[mesh];
  if (v.rows() != m.vertex_count()) {
    std::ostringstream msg;
    msg << "set_vertex_velocities: mesh " << mesh << " has " << m.vertex_count()
        << " vertices, got " << v.rows() << " rows";
    throw Error(msg.str());
  }
  if (!v.allFinite()) throw Error("set_vertex_velocities: non-finite velocity");
  for (int k = 0; k < m.vertex_count(); ++k) m.velocity_[k] = v.row(k).transpose();
  m.velocity_from_motion_ = false;
}

// ---- preparation --------------------------------------------------------------------------------

double System::rayleigh_time_step() const {
  const Particles& p = store_.core();
  if (p.size() == 0) throw Error("rayleigh_time_step: there are no particles");
  // dt_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766), G = E/(2(1+nu)), smallest over particles
  double dt = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Material& m = model_.material(p.material[i]);
    const double g = m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
    dt = std::min(dt, std::numbers::pi * p.radius[i] * std::sqrt(m.density / g) /
                          (0.1631 * m.poisson_ratio + 0.8766));
  }
  return dt;
}

double System::time_step_fraction() const {
  check_interactions();
  const std::vector<int> count = particles_per_material();
  std::vector<bool> wall(model_.material_count(), false);
  for (const PlaneWall& p : walls_.planes()) wall[p.material] = true;
  for (const TriangleMesh& m : meshes_) wall[m.material()] = true;
  double f = 0.2;
  for (int a = 0; a < model_.material_count(); ++a)
    for (int b = 0; b < model_.material_count(); ++b)
      if (count[a] > 0 && can_touch(count, wall, a, b))
        f = std::min(
            f, RestitutionCalibration::time_step_fraction(model_.interaction(a, b).restitution));
  return f;
}

std::vector<int> System::particles_per_material() const {
  std::vector<int> count(model_.material_count(), 0);
  for (int m : store_.core().material) ++count[m];
  return count;
}

// Particles of material a can touch material b: a wall or mesh of b, another particle of b, or,
// for b = a, a second particle of a (a single particle never touches itself: no interaction of a
// material with itself is needed for one sphere on a plane).
bool System::can_touch(const std::vector<int>& count, const std::vector<bool>& wall, int a,
                       int b) {
  if (count[a] == 0) return false;
  return wall[b] || (a == b ? count[a] >= 2 : count[b] > 0);
}

void System::check_interactions() const {
  const std::vector<int> count = particles_per_material();
  std::vector<bool> wall(model_.material_count(), false);
  for (const PlaneWall& p : walls_.planes()) wall[p.material] = true;
  for (const TriangleMesh& m : meshes_) wall[m.material()] = true;
  for (int a = 0; a < model_.material_count(); ++a) {
    for (int b = 0; b < model_.material_count(); ++b) {
      if (!can_touch(count, wall, a, b) || model_.has_interaction(a, b)) continue;
      std::ostringstream msg;
      msg << "no interaction between materials " << a << " and " << b
          << " (they can touch); call add_interaction(" << a << ", " << b << ", ...)";
      throw Error(msg.str());
    }
  }
}

void System::resize_histories() {
  const std::size_t n = store_.size();
  walls_.resize(store_, n);
  if (track_load_) load_.resize(n, 0.0);
}

void System::prepare() {
  if (prepared_) return;
  if (store_.size() == 0) throw Error("step: there are no particles; add some first");
  model_.update();
  check_interactions();
  rayleigh_dt_ = rayleigh_time_step();
  if (skin_ < 0.0) {
    double r_max = 0.0;
    for (double r : store_.core().radius) r_max = std::max(r_max, r);
    skin_ = 0.1 * r_max;
  }
  neighbors_.set_skin(skin_);
  resize_histories();
  if (!lists_current_) {  // (a restored state brings its lists)
    if (sort_interval_ > 0) reorder_particles();
    rebuild_lists();
  }
  prepared_ = true;
}

void System::set_sort_interval(int rebuilds) {
  if (rebuilds < 0)
    throw Error("set_sort_interval: need a number of list builds >= 0 (0: never), got " +
                std::to_string(rebuilds));
  sort_interval_ = rebuilds;
}

void System::sort_particles() {
  if (store_.size() == 0) return;
  if (prepared_) resize_histories();
  reorder_particles();
  if (prepared_) rebuild_lists();
}

// Every per-particle array (the store) is permuted alike and the pair histories follow the
// renumbered rows (the next build finds them there).
void System::reorder_particles() {
  sync_particles();
  builds_since_sort_ = 0;
  if (!cell_order_.compute(store_.core(), skin_)) return;
  store_.permute(cell_order_.order());
  neighbors_.renumber(cell_order_.new_of_old());
  pairs_follow_lists();
  mesh_contacts_.renumber(cell_order_.new_of_old());
  verlet_.invalidate();
  partition_.invalidate();
  ++sorts_;
}

void System::rebuild_lists() {
  sync_particles();
  verlet_.forget_motion();  // (its distances were from the last build's positions)
  neighbors_.build(store_.core(), walls_.planes(), meshes_);
  pairs_follow_lists();
  pairs_.place_waiting(neighbors_, store_.core().id);  // (histories of particles received)
  mesh_contacts_.follow_build(neighbors_);
  partition_.invalidate();
  lists_current_ = true;
}

int System::set_partition() {
  return partition_.update(static_cast<int>(store_.size()), max_threads(), neighbors_);
}

}  // namespace partita::dem

namespace partita::dem {

// Energy accounting across a change of the particle set between steps (energies().breakage):
// the stored energy KE + E_el (with the half-step term) just before the first change after a step
// (the lists are still those of the last pass) ... No potential energy: gravity's work is booked
// step by step from the particles' motion (m g . v dt), so where a particle is born or removed
// does not enter the books (a removed particle's m g . x, measured from an arbitrary origin, would).
void System::note_set_change() {
  if (!energy_tracking_ || !energies_.started || set_change_pending_) return;
  set_change_before_ = kinetic_energy() + half_step_term(energy_dt_) + elastic_energy();
  set_change_pending_ = true;
}

// ... and after it, at the start of the next step once the lists are built for the new set (and
// the forces, where the change made them stale): the difference left the mechanical energy with
// the change (a particle broken into fragments: what the fragment model does not give back as
// their motion and contacts). A change made by a hook (breakage's fragments) is booked
// provisionally at the end of its step already, so that the energies read after the step (a
// coupling window's audit) hold it: elastic_energy() then counts the contacts the next step
// starts from (the pairs with the histories the list build hands on, the mesh contacts of the
// last pass); what the next step's start still changes (a force pass the change made due: the
// fragments' mesh contacts, the new forces' half-step term) is booked with it.
void System::settle_set_change(bool provisional) {
  if (!set_change_pending_) return;
  const double after = kinetic_energy() + half_step_term(energy_dt_) + elastic_energy();
  energies_.breakage += set_change_before_ - after;
  // (the next step's start books its own change from here; with the lists current and the
  // forces valid it changes nothing: no search, no force pass, and the change is settled)
  if (provisional && !(lists_current() && forces_valid_))
    set_change_before_ = after;
  else
    set_change_pending_ = false;
}

// The part of KE + E_el (and the half-step term) that a change of the particles flagged in
// `in` (listed in `which`) can alter: their own kinetic and half-step terms, and every
// contact one of them is in (pairs with their histories, planes, the last pass's mesh contacts
// with the meshes' half-step power). The difference of this before and after a local change
// (System::replace_particles()) is the difference of the whole bed's sums, term by term.
double System::set_energy(const std::vector<std::size_t>& which, const std::vector<char>& in) const {
  const_cast<ContactModel&>(model_).update();
  const Particles& p = store_.core();
  const double h = 0.5 * energy_dt_, h2 = 0.125 * energy_dt_ * energy_dt_;
  const std::vector<PlaneWall>& planes = walls_.planes();
  const std::vector<Eigen::Vector3d>& plane_shear = walls_.shear(store_);
  const std::size_t np = planes.size();
  const bool have_shear = plane_shear.size() == p.size() * np;
  const Eigen::Vector3d no_shear = Eigen::Vector3d::Zero();
  double e = 0.0;
  for (const std::size_t i : which) {
    const Eigen::Vector3d &v = p.velocity[i], &w = p.angular_velocity[i], &f = p.force[i],
                          &t = p.torque[i];
    e += 0.5 * p.mass[i] * v.squaredNorm() + 0.5 * p.inertia[i] * w.squaredNorm();
    e += h * (f.dot(v) + t.dot(w)) + h2 * (f.squaredNorm() / p.mass[i] + t.squaredNorm() / p.inertia[i]);
    for (std::size_t k = 0; k < np; ++k) {
      const double delta = p.radius[i] - (p.position[i] - planes[k].point).dot(planes[k].normal);
      if (delta <= 0.0) continue;
      e += hertz_elastic_energy(model_.pair(p.material[i], planes[k].material), delta, p.radius[i],
                                have_shear ? plane_shear[i * np + k] : no_shear);
    }
  }
  const NeighborList& nl = neighbors_;
  nl.slots_touching(in, touching_);  // (the pairs in the list's order: a fixed sum)
  for (const auto& [i, s] : touching_) {
    const int j = nl.neighbors_[s];
    const double rsum = p.radius[i] + p.radius[j];
    const double delta = rsum - (p.position[i] - p.position[j]).norm();
    if (delta <= 0.0) continue;
    e += hertz_elastic_energy(model_.pair(p.material[i], p.material[j]),
                              elastic_overlap(delta, pairs_.plastic(s)),
                              p.radius[i] * p.radius[j] / rsum, pairs_.shear(s));
  }
  mesh_contacts_.for_each_contact([&](int i, const MeshContactRecord& rec, const Eigen::Vector3d& shear) {
    if (!in[i]) return;
    e += hertz_elastic_energy(model_.pair(p.material[i], rec.material), rec.delta, rec.r_eff, shear);
    e += h * rec.force.dot(meshes_[rec.mesh].velocity_at(rec.triangle, rec.barycentric));
  });
  return e;
}

double System::energy_balance_error() const {
  if (!energies_.started) return 0.0;
  return balance_error(energies_, kinetic_energy() + half_step_term(energy_dt_), elastic_energy());
}

double System::balance_error(const Energies& e, double kinetic, double elastic) {
  if (!e.started) return 0.0;
  double in = e.gravity, scale = e.kinetic_start + e.elastic_start + std::abs(e.gravity);
  for (const double w : e.wall_work) in += w, scale += std::abs(w);
  for (const double w : e.mesh_work) in += w, scale += std::abs(w);
  const double stored = (kinetic - e.kinetic_start) + (elastic - e.elastic_start);
  const double residual = in - stored - e.friction - e.damping - e.breakage - e.stiffening;
  return scale > 0.0 ? residual / scale : 0.0;
}

}  // namespace partita::dem
