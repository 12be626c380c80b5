#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/parallel.hpp"
#include "partita/dem/vtk_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <sstream>

namespace partita::dem {

namespace {

constexpr int block_size = 64;  // particles per block of the deterministic wall-force sums
constexpr int parallel_min_particles = 1024;  // fewer: one thread (a fork costs more)

std::string vec_str(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

std::int64_t feature_key(int mesh, int type, int index) {
  return (static_cast<std::int64_t>(mesh) << 40) | (static_cast<std::int64_t>(type) << 36) |
         static_cast<std::int64_t>(index);
}

}  // namespace

System::System() {
  neighbors_.clear();
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
}

std::size_t System::add_particle(const Eigen::Vector3d& x, double radius, int material,
                                 const Eigen::Vector3d& v, const Eigen::Vector3d& w,
                                 std::int64_t id) {
  sync_particles();
  const std::size_t index = particles_.size();
  if (!(radius > 0.0) || !std::isfinite(radius)) {
    std::ostringstream msg;
    msg << "add_particle " << index << ": radius must be a finite length > 0 m, got " << radius;
    throw Error(msg.str());
  }
  if (!x.allFinite() || !v.allFinite() || !w.allFinite()) {
    std::ostringstream msg;
    msg << "add_particle " << index << ": position " << vec_str(x) << ", velocity " << vec_str(v)
        << " and angular velocity " << vec_str(w) << " must be finite";
    throw Error(msg.str());
  }
  model_.check_material(material, "add_particle " + std::to_string(index));
  const double rho = model_.material(material).density;
  const double m = rho * 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  Particles& p = particles_;
  p.position.push_back(x);
  p.velocity.push_back(v);
  p.angular_velocity.push_back(w);
  p.force.push_back(Eigen::Vector3d::Zero());
  p.torque.push_back(Eigen::Vector3d::Zero());
  p.radius.push_back(radius);
  p.mass.push_back(m);
  p.inertia.push_back(0.4 * m * radius * radius);
  p.material.push_back(material);
  p.id.push_back(id < 0 ? static_cast<std::int64_t>(index) : id);
  prepared_ = false;
  forces_valid_ = false;
  packed_valid_ = false;
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
  const std::size_t first = particles_.size();
  particles_.reserve(first + positions.rows());
  for (Eigen::Index k = 0; k < positions.rows(); ++k)
    add_particle(positions.row(k).transpose(), radii[k], material);
  return first;
}

void System::set_particle_velocity(std::size_t i, const Eigen::Vector3d& v,
                                   const Eigen::Vector3d& w) {
  if (i >= particles_.size()) {
    std::ostringstream msg;
    msg << "set_particle_velocity: no particle " << i << "; there are " << particles_.size();
    throw Error(msg.str());
  }
  sync_particles();
  particles_.velocity[i] = v;
  particles_.angular_velocity[i] = w;
  forces_valid_ = false;
  packed_valid_ = false;
}

int System::add_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int material,
                      const Eigen::Vector3d& velocity) {
  model_.check_material(material, "add_plane");
  if (!(normal.norm() > 0.0) || !normal.allFinite() || !point.allFinite() ||
      !velocity.allFinite()) {
    throw Error("add_plane: need a finite point and velocity and a non-zero normal, got point " +
                vec_str(point) + ", normal " + vec_str(normal));
  }
  PlaneWall plane;
  plane.point = point;
  plane.normal = normal.normalized();
  plane.velocity = velocity;
  plane.material = material;
  plane.wall = wall_count_;
  planes_.push_back(plane);
  wall_force_.assign(wall_count_ + 1, Eigen::Vector3d::Zero());
  prepared_ = false;
  forces_valid_ = false;
  return wall_count_++;
}

int System::add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material,
                    unsigned faces) {
  model_.check_material(material, "add_box");
  if (!((hi - lo).array() > 0.0).all()) {
    throw Error("add_box: need lo < hi in every direction, got lo " + vec_str(lo) + ", hi " +
                vec_str(hi));
  }
  if ((faces & 0b111111u) == 0u) throw Error("add_box: the face mask selects no face");
  const int wall = wall_count_;
  for (int k = 0; k < 6; ++k) {
    if (!(faces & (1u << k))) continue;
    const int axis = k / 2;
    PlaneWall plane;
    plane.normal = Eigen::Vector3d::Zero();
    plane.normal[axis] = (k % 2 == 0) ? 1.0 : -1.0;
    plane.point = (k % 2 == 0) ? lo : hi;
    plane.material = material;
    plane.wall = wall;
    planes_.push_back(plane);
  }
  ++wall_count_;
  wall_force_.assign(wall_count_, Eigen::Vector3d::Zero());
  prepared_ = false;
  forces_valid_ = false;
  return wall;
}

void System::set_wall_velocity(int wall, const Eigen::Vector3d& velocity) {
  if (wall < 0 || wall >= wall_count_) {
    std::ostringstream msg;
    msg << "set_wall_velocity: unknown wall id " << wall << "; ids are 0.." << wall_count_ - 1;
    throw Error(msg.str());
  }
  for (PlaneWall& p : planes_)
    if (p.wall == wall) p.velocity = velocity;
}

int System::add_mesh(const Eigen::Ref<const Eigen::MatrixX3d>& vertices,
                     const TriangleMesh::Triangles& triangles, int material) {
  model_.check_material(material, "add_mesh");
  meshes_.emplace_back(vertices, triangles, material);
  prepared_ = false;
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

// ---- time stepping ----------------------------------------------------------------------------

double System::rayleigh_time_step() const {
  if (particles_.size() == 0) throw Error("rayleigh_time_step: there are no particles");
  // dt_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766), G = E/(2(1+nu)), smallest over particles
  double dt = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Material& m = model_.material(particles_.material[i]);
    const double g = m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
    dt = std::min(dt, std::numbers::pi * particles_.radius[i] * std::sqrt(m.density / g) /
                          (0.1631 * m.poisson_ratio + 0.8766));
  }
  return dt;
}

void System::check_interactions() const {
  std::vector<bool> used(model_.material_count(), false), used_wall(model_.material_count(), false);
  for (int m : particles_.material) used[m] = true;
  for (const PlaneWall& p : planes_) used_wall[p.material] = true;
  for (const TriangleMesh& m : meshes_) used_wall[m.material()] = true;
  for (int a = 0; a < model_.material_count(); ++a) {
    if (!used[a]) continue;
    for (int b = 0; b < model_.material_count(); ++b) {
      if (!(used[b] || used_wall[b]) || model_.has_interaction(a, b)) continue;
      std::ostringstream msg;
      msg << "no interaction between materials " << a << " and " << b
          << " (both are in use); call add_interaction(" << a << ", " << b << ", ...)";
      throw Error(msg.str());
    }
  }
}

void System::resize_histories() {
  const std::size_t n = particles_.size();
  const std::size_t np = planes_.size();
  const std::size_t old_n = mesh_slot_count_.size();  // particles at the previous resize
  const std::size_t old_np = old_n > 0 ? plane_shear_.size() / old_n : 0;
  if (old_n != n || old_np != np) {
    std::vector<Eigen::Vector3d> s(n * np, Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < std::min(n, old_n); ++i)
      for (std::size_t k = 0; k < std::min(np, old_np); ++k)
        s[i * np + k] = plane_shear_[i * old_np + k];
    plane_shear_.swap(s);
  }
  mesh_slot_count_.resize(n, 0);
  mesh_slot_key_.resize(n * max_mesh_contacts, -1);
  mesh_slot_shear_.resize(n * max_mesh_contacts, Eigen::Vector3d::Zero());
  mesh_records_.resize(n * max_mesh_contacts);
  wall_block_force_.assign(((n + block_size - 1) / block_size) * np, Eigen::Vector3d::Zero());
  wall_force_.resize(wall_count_, Eigen::Vector3d::Zero());
}

void System::prepare() {
  if (prepared_) return;
  if (particles_.size() == 0) throw Error("step: there are no particles; add some first");
  model_.update();
  check_interactions();
  rayleigh_dt_ = rayleigh_time_step();
  if (skin_ < 0.0) {
    double r_max = 0.0;
    for (double r : particles_.radius) r_max = std::max(r_max, r);
    skin_ = 0.1 * r_max;
  }
  neighbors_.set_skin(skin_);
  resize_histories();
  if (sort_interval_ > 0) reorder_particles();
  rebuild_lists();
  prepared_ = true;
}

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
  Particles& p = particles_;
  const double half = 0.5 * dt;
  const std::vector<Eigen::Vector3d>& x_build = neighbors_.position_at_build_;
  const bool have_build = x_build.size() == p.size();
  double moved2 = 0.0;  // largest squared displacement since the last neighbour build
  bool rebuild = !have_build;
  for (PlaneWall& w : planes_) w.point += dt * w.velocity;
  const int parts = set_partition();
  prepare_cross_pairs();  // for the current lists (a rebuild below prepares its own)
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
      for (int i = partition_[part]; i < partition_[part + 1]; ++i) {
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
  time_ += dt;
  ++steps_;
}

void System::run(long steps, double dt) {
  for (long s = 0; s < steps; ++s) step(dt);
}

// ---- forces -----------------------------------------------------------------------------------

// Positions, velocities and angular velocities live in packed_ while stepping (with what the pair
// loop reads about a neighbour: 96 bytes per particle, 2 cache lines instead of one per array);
// particles_ mirrors them for the caller, copied on demand.
void System::load_packed() {
  const Particles& p = particles_;
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
  Particles& p = particles_;
  for (std::size_t i = 0; i < packed_.size(); ++i) {
    p.position[i] = packed_[i].x;
    p.velocity[i] = packed_[i].v;
    p.angular_velocity[i] = packed_[i].w;
  }
  mirror_valid_ = true;
}

// Starts the force sums of a step: F = m g, T = 0.
void System::start_sums(int i) {
  particles_.force[i] = packed_[i].m * gravity_;
  particles_.torque[i].setZero();
}

void System::set_sort_interval(int rebuilds) {
  if (rebuilds < 0)
    throw Error("set_sort_interval: need a number of list builds >= 0 (0: never), got " +
                std::to_string(rebuilds));
  sort_interval_ = rebuilds;
}

void System::sort_particles() {
  if (particles_.size() == 0) return;
  if (prepared_) resize_histories();
  reorder_particles();
  if (prepared_) rebuild_lists();
}

// Counting sort of the particles by cell (cells 2 R_max + skin wide over the bounding box, in the
// order z, y, x; stable, so equal cells keep their order), then every per-particle array and
// history is permuted alike and the pair histories are renumbered for the next build.
void System::reorder_particles() {
  sync_particles();
  Particles& p = particles_;
  const int n = static_cast<int>(p.size());
  builds_since_sort_ = 0;
  if (n < 2) return;
  Eigen::Vector3d lo = p.position[0], hi = p.position[0];
  double r_max = 0.0;
  for (int i = 0; i < n; ++i) {
    lo = lo.cwiseMin(p.position[i]);
    hi = hi.cwiseMax(p.position[i]);
    r_max = std::max(r_max, p.radius[i]);
  }
  double h = std::max(2.0 * r_max + std::max(skin_, 0.0), 1e-12);
  auto dim = [&](int k) { return static_cast<long>((hi[k] - lo[k]) / h) + 1; };
  while (dim(0) * dim(1) * dim(2) > 4L * n + 64) h *= 1.26;
  const long nx = dim(0), ny = dim(1), nz = dim(2);
  auto cell = [&](double x, double o, long cells) {
    return std::clamp(static_cast<long>((x - o) / h), 0L, cells - 1);
  };
  sort_key_.resize(n);
  sort_start_.reserve(4 * static_cast<std::size_t>(n) + 65);  // the most cells: no regrowth
  sort_start_.assign(nx * ny * nz + 1, 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& x = p.position[i];
    sort_key_[i] = static_cast<int>((cell(x.z(), lo.z(), nz) * ny + cell(x.y(), lo.y(), ny)) * nx +
                                    cell(x.x(), lo.x(), nx));
    ++sort_start_[sort_key_[i] + 1];
  }
  for (std::size_t c = 1; c < sort_start_.size(); ++c) sort_start_[c] += sort_start_[c - 1];
  sort_order_.resize(n);  // new index -> old index
  for (int i = 0; i < n; ++i) sort_order_[sort_start_[sort_key_[i]]++] = i;
  bool identity = true;
  for (int k = 0; k < n && identity; ++k) identity = sort_order_[k] == k;
  if (identity) return;
  sort_new_of_old_.resize(n);
  for (int k = 0; k < n; ++k) sort_new_of_old_[sort_order_[k]] = k;
  // permute an array of `width` entries per particle (through a scratch copy that keeps its
  // capacity: no allocation once it has the largest size)
  auto permute = [&](auto& v, auto& scratch, std::size_t width) {
    if (v.size() != static_cast<std::size_t>(n) * width) return;  // not sized yet
    scratch.resize(v.size());
    for (int k = 0; k < n; ++k)
      for (std::size_t w = 0; w < width; ++w)
        scratch[k * width + w] = v[static_cast<std::size_t>(sort_order_[k]) * width + w];
    std::copy(scratch.begin(), scratch.end(), v.begin());
  };
  permute(p.position, scratch_vec3_, 1);
  permute(p.velocity, scratch_vec3_, 1);
  permute(p.angular_velocity, scratch_vec3_, 1);
  permute(p.force, scratch_vec3_, 1);
  permute(p.torque, scratch_vec3_, 1);
  permute(p.radius, scratch_real_, 1);
  permute(p.mass, scratch_real_, 1);
  permute(p.inertia, scratch_real_, 1);
  permute(p.material, scratch_int_, 1);
  permute(p.id, scratch_int64_, 1);
  permute(plane_shear_, scratch_vec3_, planes_.size());
  permute(mesh_slot_count_, scratch_int_, 1);
  permute(mesh_slot_key_, scratch_int64_, max_mesh_contacts);
  permute(mesh_slot_shear_, scratch_vec3_, max_mesh_contacts);
  permute(mesh_records_, scratch_records_, max_mesh_contacts);
  neighbors_.renumber(sort_new_of_old_);
  packed_valid_ = false;
  cross_valid_ = false;
  ++sorts_;
}

void System::rebuild_lists() {
  sync_particles();
  neighbors_.build(particles_, planes_, meshes_);
  cross_valid_ = false;
}

int System::set_partition() {
  const int n = static_cast<int>(particles_.size());
  const int blocks = (n + block_size - 1) / block_size;
  const int parts = n >= parallel_min_particles ? std::max(1, std::min(max_threads(), blocks)) : 1;
  if (cross_valid_ && static_cast<int>(partition_.size()) == parts + 1 && partition_.back() == n)
    return parts;
  // Whole blocks per part, balancing the work of the force pass: per particle a fixed cost worth
  // about two listed pairs, plus its listed pairs (known since the last build).
  const NeighborList& nl = neighbors_;
  const bool have_lists = static_cast<int>(nl.offsets_.size()) == n + 1;
  auto block_cost = [&](int b) {
    const int lo = b * block_size, hi = std::min(n, lo + block_size);
    return 2.0 * (hi - lo) + (have_lists ? nl.offsets_[hi] - nl.offsets_[lo] : 0);
  };
  double total = 0.0;
  for (int b = 0; b < blocks; ++b) total += block_cost(b);
  partition_.assign(parts + 1, n);
  partition_[0] = 0;
  double sum = 0.0;
  int t = 1;
  for (int b = 0; b + 1 < blocks && t < parts; ++b) {
    sum += block_cost(b);
    // part t starts after block b once the parts before it have their share, or when every
    // later part needs one of the blocks left
    if (sum >= total * t / parts || blocks - (b + 1) == parts - t)
      partition_[t++] = (b + 1) * block_size;
  }
  cross_valid_ = false;
  return parts;
}

int System::part_of(int i) const {
  return static_cast<int>(std::upper_bound(partition_.begin(), partition_.end(), i) -
                          partition_.begin()) -
         1;
}

void System::prepare_cross_pairs() {
  if (cross_valid_) return;
  const NeighborList& nl = neighbors_;
  const int parts = static_cast<int>(partition_.size()) - 1;
  cross_pairs_.clear();
  cross_out_begin_.assign(parts + 1, 0);
  for (int t = 0; t < parts; ++t) {
    const int hi = partition_[t + 1];
    for (int i = partition_[t]; i < hi; ++i) {
      // rows are sorted: the pairs with j beyond the part come last
      int s = nl.offsets_[i + 1];
      while (s > nl.offsets_[i] && nl.neighbors_[s - 1] >= hi) --s;
      for (; s < nl.offsets_[i + 1]; ++s) cross_pairs_.push_back({i, nl.neighbors_[s], s});
    }
    cross_out_begin_[t + 1] = static_cast<int>(cross_pairs_.size());
  }
  cross_force_.resize(cross_pairs_.size());
  // incoming: for each part, the cross pairs whose j it owns, in the order of cross_pairs_
  // (ascending i, then j)
  cross_in_begin_.assign(parts + 1, 0);
  for (const CrossPair& c : cross_pairs_) ++cross_in_begin_[part_of(c.j) + 1];
  for (int t = 0; t < parts; ++t) cross_in_begin_[t + 1] += cross_in_begin_[t];
  cross_in_.resize(cross_pairs_.size());
  counts_.assign(parts, 0);
  for (int k = 0; k < static_cast<int>(cross_pairs_.size()); ++k) {
    const int t = part_of(cross_pairs_[k].j);
    cross_in_[cross_in_begin_[t] + counts_[t]++] = k;
  }
  cross_valid_ = true;
}

void System::compute_forces(double dt, bool update_history, double kick, bool started) {
  if (!packed_valid_) load_packed();
  const int parts = set_partition();
  prepare_cross_pairs();
#pragma omp parallel if (parts > 1) num_threads(parts)
  {
    if (!started) {
#pragma omp for schedule(static, 1)
      for (int part = 0; part < parts; ++part)
        for (int i = partition_[part]; i < partition_[part + 1]; ++i) start_sums(i);
    }
    evaluate_forces(dt, update_history, kick);
  }
  reduce_wall_and_mesh_forces();
}

// Hertz-Mindlin force of the pair in slot s (i < j): F on i, the torques on i and j. Returns
// false (and settles the history) when the spheres do not overlap. Torques T_i = -cr_i n x F_t,
// T_j = -cr_j n x F_t (cr = R - delta/2, LIGGGHTS convention), rolling resistance
// T_i = -mu_r F_n R* w_rel/|w_rel| = -T_j (w_rel = omega_i - omega_j).
PARTITA_DEM_INLINE bool System::pair_force(const PackedParticle& qi, int j, int s, double dt,
                                           bool update_history, Eigen::Vector3d& fij,
                                           Eigen::Vector3d& ti, Eigen::Vector3d& tj) {
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
// row. Part t owns the particles [partition_[t], partition_[t+1]) and adds pair forces to j
// directly when j is its own; pairs reaching into a later part (cross pairs) are evaluated first,
// each once, into cross_force_, then added by both owners in the same place of their sums.
void System::evaluate_forces(double dt, bool update_history, double kick) {
  Particles& p = particles_;
  const NeighborList& nl = neighbors_;
  const int parts = static_cast<int>(partition_.size()) - 1;
  const int np = static_cast<int>(planes_.size());
  const bool have_meshes = !meshes_.empty();
  if (parts > 1) {  // the cross pairs, shared evenly among the threads
    const int n_cross = static_cast<int>(cross_pairs_.size());
#pragma omp for schedule(static)
    for (int k = 0; k < n_cross; ++k) {
      const CrossPair& c = cross_pairs_[k];
      CrossForce& cf = cross_force_[k];
      cf.touching = pair_force(packed_[c.i], c.j, c.slot, dt, update_history, cf.force_i,
                               cf.torque_i, cf.torque_j);
    }
  }
#pragma omp for schedule(static, 1)
  for (int part = 0; part < parts; ++part) {
    // pairs (k, i) from earlier parts, ascending k
    for (int k = cross_in_begin_[part]; k < cross_in_begin_[part + 1]; ++k) {
      const int c = cross_in_[k];
      const CrossForce& cf = cross_force_[c];
      if (!cf.touching) continue;
      const int j = cross_pairs_[c].j;
      p.force[j] -= cf.force_i;
      p.torque[j] += cf.torque_j;
    }
    int cross = cross_out_begin_[part];
    const int lo = partition_[part], hi = partition_[part + 1];
    for (int b = lo / block_size; b * block_size < hi; ++b) {
      // plane forces summed per block of particles, then over blocks (fixed order)
      Eigen::Vector3d* block_wall = wall_block_force_.data() + static_cast<std::size_t>(b) * np;
      for (int k = 0; k < np; ++k) block_wall[k].setZero();
      const int i_end = std::min(hi, (b + 1) * block_size);
      for (int i = b * block_size; i < i_end; ++i) {
        PackedParticle& qi = packed_[i];
        Eigen::Vector3d f = p.force[i];
        Eigen::Vector3d t = p.torque[i];
        for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
          const int j = nl.neighbors_[s];
          if (j >= hi) {  // a cross pair, already evaluated
            const CrossForce& cf = cross_force_[cross++];
            if (cf.touching) f += cf.force_i, t += cf.torque_i;
            continue;
          }
          Eigen::Vector3d fij, ti, tj;
          if (!pair_force(qi, j, s, dt, update_history, fij, ti, tj)) continue;
          f += fij;
          t += ti;
          p.force[j] -= fij;
          p.torque[j] += tj;
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
          Eigen::Vector3d& shear = plane_shear_[static_cast<std::size_t>(i) * np + k];
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
          block_wall[k] -= fw;
        }
        if (have_meshes) {  // own accumulators: f and t keep their registers
          Eigen::Vector3d fm = Eigen::Vector3d::Zero(), tm = Eigen::Vector3d::Zero();
          mesh_contacts(i, dt, update_history, fm, tm);
          f += fm;
          t += tm;
        }
        p.force[i] = f;
        p.torque[i] = t;
        if (kick > 0.0) {  // (no other row reads particle i any more in this pass)
          qi.v += (kick / qi.m) * f;
          qi.w += (kick / p.inertia[i]) * t;
        }
      }
    }
  }
}

void System::reduce_wall_and_mesh_forces() {
  const int n = static_cast<int>(particles_.size());
  const int np = static_cast<int>(planes_.size());
  const int blocks = (n + block_size - 1) / block_size;
  const bool have_meshes = !meshes_.empty();
  // Wall totals (fixed order: blocks, then planes).
  for (Eigen::Vector3d& w : wall_force_) w.setZero();
  for (int b = 0; b < blocks; ++b)
    for (int k = 0; k < np; ++k)
      wall_force_[planes_[k].wall] += wall_block_force_[static_cast<std::size_t>(b) * np + k];
  // Mesh forces: particles in order, each contact's reaction on its triangle, shared among the
  // triangle's vertices with the barycentric weights of the contact point.
  if (!have_meshes) return;
  for (TriangleMesh& m : meshes_) {
    m.triangle_force_.setZero();
    m.vertex_force_.setZero();
  }
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c < mesh_slot_count_[i]; ++c) {
      const MeshContactRecord& rec =
          mesh_records_[static_cast<std::size_t>(i) * max_mesh_contacts + c];
      TriangleMesh& m = meshes_[rec.mesh];
      m.triangle_force_.row(rec.triangle) -= rec.force.transpose();
      const auto& tri = m.triangle(rec.triangle);
      for (int k = 0; k < 3; ++k)
        m.vertex_force_.row(tri[k]) -= rec.barycentric[k] * rec.force.transpose();
    }
  }
}

// Contacts of particle i with the meshes, each counted once:
//  - candidates: triangles whose closest point is within R (face, edge or vertex feature) and
//    is a local closest point of the mesh surface (an edge or vertex only where no triangle
//    sharing it comes nearer: on a fine flat mesh only the face under the centre touches);
//  - accepted in the order faces, edges, vertices (then by distance): a face always; an edge
//    only if no accepted face has it as an edge; a vertex only if no accepted face or edge has
//    it; and any contact only if its normal differs from all accepted ones (a sphere cannot
//    touch two surfaces with the same normal: coplanar neighbours sharing the point).
void System::mesh_contacts(int i, double dt, bool update_history, Eigen::Vector3d& f,
                           Eigen::Vector3d& t) {
  struct Candidate {
    int mesh, triangle, type, feature;
    TriangleClosestPoint cp;
    double dist2;
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
  const PackedParticle& q = packed_[i];
  const NeighborList& nl = neighbors_;
  const Eigen::Vector3d& x = q.x;
  const double r = q.r;
  for (int k = nl.mesh_offsets_[i]; k < nl.mesh_offsets_[i + 1]; ++k) {
    const MeshCandidate mc = nl.mesh_candidates_[k];
    const TriangleMesh& m = meshes_[mc.mesh];
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
    if (dist > 1e-12 * r) {
      c.normal = (x - c.cp.point) / dist;
    } else {
      const auto& tri = m.triangle(mc.triangle);
      c.normal = (m.position_[tri[1]] - m.position_[tri[0]])
                     .cross(m.position_[tri[2]] - m.position_[tri[0]])
                     .normalized();
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
  std::sort(cand, cand + nc, before);
  int accepted[max_mesh_contacts];
  int na = 0;
  constexpr double same_normal = 1.0 - 5.0e-5;  // about 0.6 degrees
  for (int c = 0; c < nc; ++c) {
    const Candidate& k = cand[c];
    bool keep = true;
    for (int a = 0; a < na && keep; ++a) {
      const Candidate& acc = cand[accepted[a]];
      if (acc.normal.dot(k.normal) > same_normal) keep = false;
      if (acc.mesh != k.mesh) continue;
      if (acc.type == k.type && acc.feature == k.feature) keep = false;
      const TriangleMesh& m = meshes_[k.mesh];
      if (k.type == TriangleClosestPoint::edge && acc.type == TriangleClosestPoint::face) {
        for (int e : m.triangle_edges(acc.triangle)) keep = keep && e != k.feature;
      } else if (k.type == TriangleClosestPoint::vertex) {
        if (acc.type == TriangleClosestPoint::face)
          for (int v : m.triangle(acc.triangle)) keep = keep && v != k.feature;
        else if (acc.type == TriangleClosestPoint::edge)
          for (int v : m.edge(acc.feature)) keep = keep && v != k.feature;
      }
    }
    if (keep && na < max_mesh_contacts) accepted[na++] = c;
  }
  // Histories: the previous step's slots of particle i, matched by feature key.
  const std::size_t base = static_cast<std::size_t>(i) * max_mesh_contacts;
  std::int64_t old_key[max_mesh_contacts];
  Eigen::Vector3d old_shear[max_mesh_contacts];
  const int n_old = mesh_slot_count_[i];
  for (int s = 0; s < n_old; ++s) {
    old_key[s] = mesh_slot_key_[base + s];
    old_shear[s] = mesh_slot_shear_[base + s];
  }
  // A contact keeps its history when its feature stays (same key) and also when it passes to
  // a neighbouring feature of the same mesh, rolling or sliding across triangle boundaries: an
  // unmatched old contact whose point (the same material point of the wall, at the current
  // vertex positions) lies within the new contact radius sqrt(R delta) hands its history on.
  int from_old[max_mesh_contacts];
  bool old_taken[max_mesh_contacts] = {};
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
    const TriangleMesh& m = meshes_[k.mesh];
    double best = r * (r - std::sqrt(k.dist2));  // (contact radius)^2
    for (int s = 0; s < n_old; ++s) {
      const MeshContactRecord& rec = mesh_records_[base + s];
      if (old_taken[s] || rec.mesh != k.mesh) continue;
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
    const TriangleMesh& m = meshes_[k.mesh];
    const std::int64_t key = feature_key(k.mesh, k.type, k.feature);
    Eigen::Vector3d shear =
        from_old[a] >= 0 ? old_shear[from_old[a]] : Eigen::Vector3d::Zero().eval();
    const auto& tri = m.triangle(k.triangle);
    // wall velocity at the contact point: barycentric interpolation of the vertex velocities
    const Eigen::Vector3d v_wall = k.cp.barycentric[0] * m.velocity_[tri[0]] +
                                   k.cp.barycentric[1] * m.velocity_[tri[1]] +
                                   k.cp.barycentric[2] * m.velocity_[tri[2]];
    const double delta = r - std::sqrt(k.dist2);
    const double cr = r - 0.5 * delta;
    const PairParameters& pp = model_.pair(q.material, m.material());
    Eigen::Vector3d fw, ft;
    const double fn = hertz_mindlin(pp, delta, r, q.m, k.normal, q.v - v_wall, cr * q.w, shear, dt,
                                    update_history, fw, ft);
    f += fw;
    t -= cr * k.normal.cross(ft);
    if (pp.rolling_friction > 0.0) {
      const double wn = q.w.norm();
      if (wn > 0.0) t -= (pp.rolling_friction * std::abs(fn) * r / wn) * q.w;
    }
    mesh_slot_key_[base + a] = key;
    mesh_slot_shear_[base + a] = shear;
    MeshContactRecord& rec = mesh_records_[base + a];
    rec.mesh = k.mesh;
    rec.triangle = k.triangle;
    rec.barycentric = k.cp.barycentric;
    rec.force = fw;
    rec.delta = delta;
    rec.r_eff = r;
    rec.material = m.material();
  }
  mesh_slot_count_[i] = na;
}

// ---- state ------------------------------------------------------------------------------------

SystemState System::save_state() const {
  sync_particles();
  SystemState s;
  s.particles_ = particles_;
  s.planes_ = planes_;
  s.meshes_ = meshes_;
  s.neighbors_ = neighbors_;
  s.plane_shear_ = plane_shear_;
  s.mesh_slot_key_ = mesh_slot_key_;
  s.mesh_slot_shear_ = mesh_slot_shear_;
  s.mesh_slot_count_ = mesh_slot_count_;
  s.mesh_records_ = mesh_records_;
  s.wall_force_ = wall_force_;
  s.time_ = time_;
  s.steps_ = steps_;
  s.forces_valid_ = forces_valid_;
  s.prepared_ = prepared_;
  s.builds_since_sort_ = builds_since_sort_;
  return s;
}

void System::restore_state(const SystemState& s) {
  bool same = s.particles_.size() == particles_.size() && s.planes_.size() == planes_.size() &&
              s.meshes_.size() == meshes_.size();
  for (std::size_t m = 0; same && m < meshes_.size(); ++m)
    same = s.meshes_[m].vertex_count() == meshes_[m].vertex_count() &&
           s.meshes_[m].triangle_count() == meshes_[m].triangle_count();
  if (!same) {
    std::ostringstream msg;
    msg << "restore_state: the state has " << s.particles_.size() << " particles, "
        << s.planes_.size() << " planes and " << s.meshes_.size() << " meshes; this system has "
        << particles_.size() << ", " << planes_.size() << " and " << meshes_.size()
        << " (a state can only be restored into the system it came from)";
    throw Error(msg.str());
  }
  particles_ = s.particles_;
  mirror_valid_ = true;
  packed_valid_ = false;
  planes_ = s.planes_;
  meshes_ = s.meshes_;
  neighbors_ = s.neighbors_;
  plane_shear_ = s.plane_shear_;
  mesh_slot_key_ = s.mesh_slot_key_;
  mesh_slot_shear_ = s.mesh_slot_shear_;
  mesh_slot_count_ = s.mesh_slot_count_;
  mesh_records_ = s.mesh_records_;
  wall_force_ = s.wall_force_;
  time_ = s.time_;
  steps_ = s.steps_;
  forces_valid_ = s.forces_valid_;
  builds_since_sort_ = s.builds_since_sort_;
  cross_valid_ = false;
  if (!s.prepared_) prepared_ = false;
}

// ---- monitors ---------------------------------------------------------------------------------

double System::kinetic_energy() const {
  sync_particles();
  double e = 0.0;
  const Particles& p = particles_;
  for (std::size_t i = 0; i < p.size(); ++i)
    e += 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
         0.5 * p.inertia[i] * p.angular_velocity[i].squaredNorm();
  return e;
}

double System::potential_energy() const {
  sync_particles();
  double e = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i)
    e -= particles_.mass[i] * gravity_.dot(particles_.position[i]);
  return e;
}

double System::elastic_energy() const {
  sync_particles();
  const_cast<ContactModel&>(model_).update();
  const Particles& p = particles_;
  const NeighborList& nl = neighbors_;
  double e = 0.0;
  const int n = static_cast<int>(p.size());
  const Eigen::Vector3d no_shear = Eigen::Vector3d::Zero();
  auto pair_energy = [&](int i, int j, const Eigen::Vector3d& shear) {
    const double rsum = p.radius[i] + p.radius[j];
    const double delta = rsum - (p.position[i] - p.position[j]).norm();
    if (delta <= 0.0) return 0.0;
    return hertz_elastic_energy(model_.pair(p.material[i], p.material[j]), delta,
                                p.radius[i] * p.radius[j] / rsum, shear);
  };
  if (prepared_ && nl.offsets_.size() == p.size() + 1) {
    for (int i = 0; i < n; ++i)
      for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s)
        e += pair_energy(i, nl.neighbors_[s], nl.shear_[s]);
  } else {  // before the first step: no lists yet, all pairs (no tangential history either)
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) e += pair_energy(i, j, no_shear);
  }
  const std::size_t np = planes_.size();
  const bool have_shear = plane_shear_.size() == p.size() * np;
  for (int i = 0; i < n; ++i)
    for (std::size_t k = 0; k < np; ++k) {
      const double delta = p.radius[i] - (p.position[i] - planes_[k].point).dot(planes_[k].normal);
      if (delta <= 0.0) continue;
      e += hertz_elastic_energy(model_.pair(p.material[i], planes_[k].material), delta, p.radius[i],
                                have_shear ? plane_shear_[i * np + k] : no_shear);
    }
  if (mesh_slot_count_.size() == p.size()) {
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < mesh_slot_count_[i]; ++c) {
        const std::size_t s = static_cast<std::size_t>(i) * max_mesh_contacts + c;
        const MeshContactRecord& rec = mesh_records_[s];
        e += hertz_elastic_energy(model_.pair(p.material[i], rec.material), rec.delta, rec.r_eff,
                                  mesh_slot_shear_[s]);
      }
  }
  return e;
}

Eigen::Vector3d System::wall_force(int wall) const {
  if (wall < 0 || wall >= wall_count_) {
    std::ostringstream msg;
    msg << "wall_force: unknown wall id " << wall << "; ids are 0.." << wall_count_ - 1;
    throw Error(msg.str());
  }
  return wall_force_[wall];
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
  const Particles& p = particles_;
  const NeighborList& nl = neighbors_;
  std::size_t count = 0;
  if (nl.offsets_.size() != p.size() + 1) return 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s) {
      const int j = nl.neighbors_[s];
      const double rsum = p.radius[i] + p.radius[j];
      if ((p.position[i] - p.position[j]).squaredNorm() < rsum * rsum) ++count;
    }
  return count;
}

double System::mean_contacts_per_particle() const {
  return particles_.size() == 0 ? 0.0 : 2.0 * contact_count() / particles_.size();
}

// ---- output -----------------------------------------------------------------------------------

void System::write_particles_vtp(const std::string& path) const {
  sync_particles();
  const Particles& p = particles_;
  const std::size_t n = p.size();
  std::vector<VtkArray> data(5);
  data[0] = {"radius", 1, false, std::vector<double>(p.radius)};
  data[1] = {"id", 1, true, {}};
  data[2] = {"velocity", 3, false, {}};
  data[3] = {"angular_velocity", 3, false, {}};
  data[4] = {"force", 3, false, {}};
  for (std::size_t i = 0; i < n; ++i) {
    data[1].values.push_back(static_cast<double>(p.id[i]));
    for (int k = 0; k < 3; ++k) {
      data[2].values.push_back(p.velocity[i][k]);
      data[3].values.push_back(p.angular_velocity[i][k]);
      data[4].values.push_back(p.force[i][k]);
    }
  }
  VtkWriter::write_points(path, p.position, data);
}

void System::write_mesh_vtp(int mesh, const std::string& path) const {
  check_mesh(mesh, "write_mesh_vtp");
  const TriangleMesh& m = meshes_[mesh];
  std::vector<std::array<int, 3>> tris(m.triangle_count());
  for (int t = 0; t < m.triangle_count(); ++t) tris[t] = m.triangle(t);
  std::vector<VtkArray> point_data(2), cell_data(1);
  point_data[0] = {"velocity", 3, false, {}};
  point_data[1] = {"force", 3, false, {}};
  cell_data[0] = {"force", 3, false, {}};
  for (int v = 0; v < m.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) {
      point_data[0].values.push_back(m.velocities()[v][k]);
      point_data[1].values.push_back(m.vertex_forces()(v, k));
    }
  for (int tt = 0; tt < m.triangle_count(); ++tt)
    for (int k = 0; k < 3; ++k) cell_data[0].values.push_back(m.triangle_forces()(tt, k));
  VtkWriter::write_triangles(path, m.positions(), tris, point_data, cell_data);
}

}  // namespace partita::dem
