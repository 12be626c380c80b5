// The DEM adapter proper: the Solver contract (meshes, read/write, advance, checkpoint, restart,
// output, the state check) over dem::System. Its schema: dem_schema.cpp; its building from the
// case: dem_build.cpp; its monitors: dem_monitors.cpp.

#include "dem_adapter.hpp"
#include "dem_ranks.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "partita/adapters/dem_output.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/dem/breakage.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/grading.hpp"
#include "partita/dem/lammps_data.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::adapters {

// On ranks the handle forgets this object's loops (the app may still hold it: a run whose set-up
// failed after this solver was built; it then ends the ranks itself).
DemAdapter::~DemAdapter() {
  if (ranks_) ranks_->ranks->claim(nullptr, nullptr);
}

const dem::Breakage* DemAdapter::breakage() const {
  return breakage_ < 0 ? nullptr : &static_cast<const dem::Breakage&>(system_.hook(breakage_));
}

std::size_t DemAdapter::find(std::string_view mesh, bool* centres) const {
  for (std::size_t k = 0; k < meshes_dem_.size(); ++k) {
    const auto& m = meshes_dem_[k];
    if (mesh == m.name || mesh == m.name + "_centres") {
      *centres = mesh != m.name;
      return k;
    }
  }
  throw Error("dem '" + name_ + "' has no mesh '" + std::string(mesh) + "'");
}

void DemAdapter::read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) {
  bool centres = false;
  const std::size_t k = find(mesh, &centres);
  CouplingMesh& cm = meshes_dem_[k];
  const bool attached = centres && data == "attached";
  if (!attached && (centres || data != "displacement"))
    throw Error("dem '" + name_ + "' reads 'displacement' on mesh '" + cm.name +
                "' and 'attached' on '" + cm.name + "_centres', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  if (on_ranks()) {  // every rank's copy of the mesh alike (dem_ranks.cpp)
    lead_read(k, attached ? OnRanks::kAttached : OnRanks::kDisplacement, values);
    return;
  }
  if (attached) {
    set_attached(cm, values);
    return;
  }
  // x = X + d: the vertices follow the other side's displacement (no allocation: same size).
  cm.positions = cm.reference + values;
  system_.set_vertex_positions(cm.id, cm.positions);
}

void DemAdapter::set_attached(const CouplingMesh& cm, const Eigen::MatrixXd& values) {
  // every window, mostly unchanged: only the triangles whose state changes are set (setting
  // one to its state is a no-op); a count that does not fit goes through the checked call
  const dem::TriangleMesh& m = system_.mesh(cm.id);
  const bool fits = values.rows() == m.triangle_count();
  for (Eigen::Index t = 0; t < values.rows(); ++t) {
    const bool active = values(t, 0) >= 0.5;
    if (!fits || active != m.triangle_active(static_cast<int>(t)))
      system_.set_triangle_active(cm.id, static_cast<int>(t), active);
  }
}

void DemAdapter::write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) {
  bool centres = false;
  const std::size_t k = find(mesh, &centres);
  const CouplingMesh& cm = meshes_dem_[k];
  if (!centres && data != "force")
    throw Error("dem '" + name_ + "' writes only 'force' on mesh '" + cm.name + "'");
  if (centres && data != "force" && data != "traction")
    throw Error("dem '" + name_ + "' writes 'force' and 'traction' on mesh '" + cm.name +
                "_centres', not '" + std::string(data) + "'");
  if (on_ranks()) {  // the forces summed over the ranks (dem_ranks.cpp)
    lead_write(k,
               !centres          ? OnRanks::kVertexForce
               : data == "force" ? OnRanks::kTriangleForce
                                 : OnRanks::kTraction,
               values);
    return;
  }
  if (!centres) {
    values = system_.vertex_forces(cm.id);
    return;
  }
  const Eigen::MatrixX3d& f = system_.triangle_forces(cm.id);
  if (data == "force") {
    values = f;
  } else if (data == "traction") {
    // t_i = f_i / A_i (seed 000, Algorithm 1), with the reference areas: column by column
    // (contiguous, two divisions per instruction; the same quotients as row by row)
    values.resize(f.rows(), 3);
    values.array() = f.array().colwise() / cm.areas.array();
  } else {
    throw Error("dem '" + name_ + "' writes 'force' and 'traction' on mesh '" + cm.name +
                "_centres', not '" + std::string(data) + "'");
  }
}

double DemAdapter::stable_time_step() const {
  if (on_ranks()) return ranks_->stable;  // over every particle at the start (the set is fixed)
  // dt_R is a minimum over the particles (O(N) square roots): recomputed only when the particle
  // set changed (breakage adds fragments), not at every step that asks for it.
  // (Restoring a checkpoint or a restart file resets stable_for_count_.)
  if (system_.particle_count() != stable_for_count_ || time_step_fraction_ != stable_fraction_) {
    stable_ = time_step_fraction_ * system_.rayleigh_time_step();
    stable_for_count_ = system_.particle_count();
    stable_fraction_ = time_step_fraction_;
  }
  return stable_;
}

void DemAdapter::advance(double dt) {
  if (on_ranks()) {
    lead_advance(dt);
    return;
  }
  // walls with a velocity table move with the factor at the middle of the step (exact
  // displacement where the step lies within one row interval of the table)
  for (const auto& w : walls_)
    if (w.moving) system_.set_wall_velocity(w.id, w.velocity * w.table(system_.time() + 0.5 * dt));
  // Fragments lower the stable step. Between windows the core follows it (auto substeps) or
  // stops with the key to change (a fixed count); within a window, a step that breakage made
  // too long is split here into as many equal steps as the new stable step needs.
  int parts = 1;
  if (breakage_ >= 0) {
    const double stable = stable_time_step();
    if (coupling::TimeWindow::longer_than(dt, stable))
      parts = coupling::TimeWindow::substeps_for(dt, stable);
  }
  try {
    for (int k = 0; k < parts; ++k) system_.step(dt / parts);
  } catch (const dem::Error& e) {
    throw Error("dem '" + name_ + "' at t = " + fmt::format("{:.6g}", system_.time()) +
                " s: " + e.what());
  }
  // the work the meshes' motion did on the particles over this step (no allocation: same sizes)
  // (no allocation: same sizes)
  for (auto& cm : meshes_dem_) cm.audit.motion_step(cm.positions, system_.vertex_forces(cm.id));
}

std::optional<double> DemAdapter::interface_work(std::string_view mesh) const {
  bool centres = false;
  const CouplingMesh& cm = meshes_dem_[find(mesh, &centres)];
  // what M_centres reads ("attached") moves nothing: the motion's work is M's alone (counted
  // once when a case exchanges on both)
  if (centres) return std::nullopt;
  return cm.audit.work();
}

void DemAdapter::save_checkpoint() {
  if (on_ranks())
    ranks_->checkpoint = lead_restart();  // the split bed gathered to the leader (dem_ranks.cpp)
  else
    checkpoint_ = system_.save_state();
  for (auto& cm : meshes_dem_) cm.audit.save_checkpoint();
  has_checkpoint_ = true;
}

void DemAdapter::restore_checkpoint() {
  if (!has_checkpoint_)
    throw Error("dem '" + name_ + "': restore_checkpoint() before save_checkpoint()");
  if (on_ranks()) {
    lead_restore(ranks_->checkpoint);
  } else {
    system_.restore_state(checkpoint_);
    stable_for_count_ = kNoCount;
  }
  for (auto& cm : meshes_dem_) cm.audit.restore_checkpoint();
}

void DemAdapter::write_output(const OutputFrame& frame) {
  if (on_ranks()) {
    lead_output(frame);
    return;
  }
  files_.clear();
  // (a new run's first frame: the pieces of an earlier run on ranks into this folder go)
  if (frame.index == 0) remove_particle_pieces(frame.vtk_directory, frame.prefix);
  const std::string pfile = fmt::format("{}_particles_{:06d}.vtp", frame.prefix, frame.index);
  write_particles_vtp(system_, frame.vtk_directory / pfile, frame.vtk);
  files_.emplace_back("particles", pfile);
  for (const auto& m : meshes_dem_) {
    const std::string mfile = fmt::format("{}_{}_{:06d}.vtp", frame.prefix, m.name, frame.index);
    write_mesh_vtp(system_, m.id, frame.vtk_directory / mfile, frame.vtk);
    files_.emplace_back(m.name, mfile);
  }
  if (breakage_ >= 0) write_grading(frame, system_.particles());
  if (particles_file_ == "every-output") {
    const std::filesystem::path dir = frame.vtk_directory.parent_path() / "particles";
    std::filesystem::create_directories(dir);
    write_particles_file(dir / fmt::format("{}_{:06d}.data", frame.prefix, frame.index));
  }
}

void DemAdapter::finalize() {
  if (on_ranks()) {
    if (particles_file_ != "none") lead_particles_file(output_dir_ / (name_ + ".data"));
    end_others(0);  // the others' loops end with the run (nothing of theirs is left to write)
    return;
  }
  if (particles_file_ != "none") write_particles_file(output_dir_ / (name_ + ".data"));
}

void DemAdapter::write_particles_file(const std::filesystem::path& file) const {
  write_particles_file(system_.particles(), file);
}

void DemAdapter::write_particles_file(const dem::Particles& particles,
                                      const std::filesystem::path& file) const {
  std::vector<double> density;
  for (int m = 0; m < system_.contact_model().material_count(); ++m)
    density.push_back(system_.contact_model().material(m).density);
  try {
    dem::LammpsData::of(particles, density)
        .write(file.string(),
               fmt::format("partita DEM '{}' at t = {:.17g} s", name_, system_.time()));
  } catch (const dem::Error& e) {
    throw Error("dem '" + name_ + "': " + e.what());
  }
}

// Grading at each output time: rows time, diameter, mass fraction passing, appended to
// DIR/<participant>_grading.csv (DIR the run's output folder, the parent of vtk/).
void DemAdapter::write_grading(const OutputFrame& frame, const dem::Particles& particles) const {
  const std::filesystem::path file =
      frame.vtk_directory.parent_path() / (frame.prefix + "_grading.csv");
  const bool header = frame.index == 0 || !std::filesystem::exists(file);
  std::ofstream out(file, header ? std::ios::trunc : std::ios::app);
  if (!out) throw Error("dem '" + name_ + "': cannot write the grading to " + file.string());
  if (header) out << "time_s,diameter_m,passing\n";
  for (const dem::Grading::Point& g : dem::Grading::cumulative(particles))
    out << fmt::format("{:.9g},{:.9g},{:.9g}\n", frame.time, g.size, g.passing);
}

void DemAdapter::write_restart(BinaryWriter& out) const {
  if (on_ranks()) {
    // the split bed's restart (dem::SplitRestart: gathered to rank 0), resumed on any number of
    // ranks
    out.section("dem on ranks");
    out.bytes(lead_restart());
    out.section("dem interface work");
    for (const auto& cm : meshes_dem_) cm.audit.save(out);
    return;
  }
  out.section("dem");
  std::ostringstream state;
  system_.write_state(state);  // the DEM's own versioned format: particles with ids, contact
                               // histories, walls, mesh vertices, hooks' counters and RNG state
  out.bytes(state.str());
  out.section("dem interface work");
  for (const auto& cm : meshes_dem_) cm.audit.save(out);
}

void DemAdapter::read_restart(BinaryReader& in) {
  // a restart file of a run on ranks (mpirun -n N partita run) holds the split bed in a section
  // of its own: it resumes on ranks, and one written without mpirun resumes without
  const auto expect = [&](const char* section, const char* hint) {
    try {
      in.expect_section(section);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + hint);
    }
  };
  if (on_ranks()) {
    expect("dem on ranks",
           " (a restart file written without mpirun resumes without mpirun: the DEM on ranks "
           "keeps its own section)");
    if (const std::string astray = lead_resume(in.bytes(), in.source()); !astray.empty())
      throw Error(in.source() + ": the DEM state of '" + name_ + "' cannot be resumed: " + astray);
    in.expect_section("dem interface work");
    for (auto& cm : meshes_dem_) cm.audit.load(in, "vertices of mesh '" + cm.name + "'");
    return;
  }
  expect("dem",
         " (a restart file written on ranks, mpirun -n N partita run, resumes on ranks: "
         "mpirun -n M partita run CASE --resume DIR)");
  std::istringstream state(in.bytes());
  try {
    system_.read_state(state);
    stable_for_count_ = kNoCount;
  } catch (const dem::Error& e) {
    throw Error(in.source() + ": the DEM state of '" + name_ + "': " + e.what());
  }
  // a state whose particles are not finite or lie beyond the domain (a damaged or foreign file)
  // is refused here, with the particle, rather than by the neighbour grid at the first step
  if (const std::string astray = particle_astray(true); !astray.empty())
    throw Error(in.source() + ": the DEM state of '" + name_ + "' cannot be resumed: " + astray);
  in.expect_section("dem interface work");
  for (auto& cm : meshes_dem_) cm.audit.load(in, "vertices of mesh '" + cm.name + "'");
}

void DemAdapter::add_coupling_mesh(const std::string& name, const Mesh& mesh, int material,
                                   bool one_sided) {
  CouplingMesh cm;
  cm.name = name;
  cm.reference = mesh.points();
  cm.positions = mesh.points();
  cm.areas = mesh.triangle_areas();
  cm.id = system_.add_mesh(mesh.points(), mesh.triangles(), material);
  system_.set_mesh_one_sided(cm.id, one_sided);
  cm.audit = InterfaceWork::motion(mesh.points(), system_.vertex_forces(cm.id));
  InterfaceMesh vertices;
  vertices.mesh = Mesh(name, mesh.points(), mesh.triangles());
  vertices.reads.push_back(DataSpec{"displacement", 3, "m", DataKind::intensive});
  vertices.writes.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
  InterfaceMesh centres;
  centres.mesh = Mesh(name + "_centres", mesh.triangle_centroids());
  centres.mesh.set_weights(cm.areas);  // each centre stands for its triangle's area
  centres.writes.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
  centres.writes.push_back(DataSpec{"traction", 3, "Pa", DataKind::intensive});
  // a triangle whose value is below 1/2 leaves the contacts (its surface has gone: the face of
  // an eroded FE element, FemAdapter's N_centres)
  centres.reads.push_back(DataSpec{"attached", 1, "", DataKind::intensive});
  meshes_.push_back(std::move(vertices));
  meshes_.push_back(std::move(centres));
  for (Eigen::Index i = 0; i < cm.reference.rows(); ++i) {
    domain_lo_ = domain_lo_.cwiseMin(cm.reference.row(i).transpose());
    domain_hi_ = domain_hi_.cwiseMax(cm.reference.row(i).transpose());
  }
  meshes_dem_.push_back(std::move(cm));
  // the mesh's material may be a new partner with a lower restitution
  if (time_step_fraction_auto_) time_step_fraction_ = system_.time_step_fraction();
}

void DemAdapter::receive_mesh(const std::string& name, const Mesh& mesh) {
  for (std::size_t k = 0; k < requests_.size(); ++k)
    if (requests_[k].name == name) {
      try {
        add_coupling_mesh(name, mesh, request_materials_[k], request_one_sided_[k] != 0);
      } catch (const dem::Error& e) {
        requests_[k].where.fail(std::string("cannot use this surface as a contact mesh: ") +
                                e.what());
      }
      if (!lost_margin_given_) lost_margin_ = default_lost_margin();
      if (on_ranks()) {
        // (the leader) the others add it alike; every rank cuts the bed once all are in
        if (ranks_->ranks->leads()) lead_mesh(name, mesh);
        if (++ranks_->meshes_received == requests_.size()) ranks_split();
      }
      return;
    }
  throw Error("dem '" + name_ + "' asked for no mesh '" + name + "'");
}

double DemAdapter::default_lost_margin() const {
  double d_max = 0.0;
  for (const double r : system_.particles().radius) d_max = std::max(d_max, 2.0 * r);
  return std::max((domain_hi_ - domain_lo_).maxCoeff(), kLostDiameters * d_max);
}

std::string DemAdapter::check_state() const {
  return on_ranks() ? lead_check() : particle_astray(false);
}

std::string DemAdapter::particle_astray(bool restored) const {
  // the first particle (lowest index) that is not finite or lies beyond the margin, if any
  const std::ptrdiff_t astray = system_.first_particle_astray(domain_lo_, domain_hi_, lost_margin_);
  if (astray < 0) return {};
  return astray_message(static_cast<std::size_t>(astray), restored);
}

std::string DemAdapter::astray_message(std::size_t i, bool restored) const {
  const dem::Particles& p = system_.particles();
  if (restored)
    return fmt::format(
        "particle id {} (index {}) at ({:.6g}, {:.6g}, {:.6g}) m with velocity ({:.6g}, {:.6g}, "
        "{:.6g}) m/s is not finite or lies outside the domain [{:.4g} {:.4g} {:.4g}] .. [{:.4g} "
        "{:.4g} {:.4g}] m by more than lost_margin = {:.3g} m (a damaged restart file, or one "
        "of another case)",
        p.id[i], i, p.position[i].x(), p.position[i].y(), p.position[i].z(), p.velocity[i].x(),
        p.velocity[i].y(), p.velocity[i].z(), domain_lo_.x(), domain_lo_.y(), domain_lo_.z(),
        domain_hi_.x(), domain_hi_.y(), domain_hi_.z(), lost_margin_);
  if (!p.position[i].allFinite() || !p.velocity[i].allFinite())
    return fmt::format(
        "particle {} has a non-finite position or velocity: the DEM step is unstable; lower "
        "time_step_fraction (now {:.3g}) or check the materials and the coupled loads",
        p.id[i], time_step_fraction_);
  const Eigen::Vector3d& x = p.position[i];
  const double out = std::max((domain_lo_ - x).maxCoeff(), (x - domain_hi_).maxCoeff());
  return fmt::format(
      "particle {} is lost: at ({:.4g}, {:.4g}, {:.4g}) m it lies {:.3g} m outside the "
      "domain [{:.4g} {:.4g} {:.4g}] .. [{:.4g} {:.4g} {:.4g}] m (walls, meshes and the "
      "particles at the start) by more than lost_margin = {:.3g} m; a wall or mesh lets "
      "particles through (an open face, an overlap too large for the time step) or the run is "
      "diverging; if the particle may go that far, raise the participant's key lost_margin",
      p.id[i], x.x(), x.y(), x.z(), out, domain_lo_.x(), domain_lo_.y(), domain_lo_.z(),
      domain_hi_.x(), domain_hi_.y(), domain_hi_.z(), lost_margin_);
}

}  // namespace partita::adapters
