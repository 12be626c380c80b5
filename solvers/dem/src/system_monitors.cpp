// System: monitors (energies, forces, contact counts) and VTK output.
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/vtk_writer.hpp"

#include <sstream>

namespace partita::dem {

// ---- monitors ---------------------------------------------------------------------------------

double System::kinetic_energy() const {
  sync_particles();
  double e = 0.0;
  const Particles& p = store_.core();
  for (std::size_t i = 0; i < p.size(); ++i)
    e += 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
         0.5 * p.inertia[i] * p.angular_velocity[i].squaredNorm();
  return e;
}

double System::potential_energy() const {
  sync_particles();
  const Particles& p = store_.core();
  double e = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) e -= p.mass[i] * gravity_.dot(p.position[i]);
  return e;
}

double System::elastic_energy() const {
  sync_particles();
  const_cast<ContactModel&>(model_).update();
  const Particles& p = store_.core();
  const std::vector<Eigen::Vector3d>& plane_shear = walls_.shear(store_);
  const std::vector<PlaneWall>& planes = walls_.planes();
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
  if (lists_current_ && nl.offsets_.size() == p.size() + 1) {
    for (int i = 0; i < n; ++i)
      for (int s = nl.offsets_[i]; s < nl.offsets_[i + 1]; ++s)
        e += pair_energy(i, nl.neighbors_[s], pairs_.shear(s));
  } else {  // before the first step: no lists yet, all pairs (no tangential history either)
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) e += pair_energy(i, j, no_shear);
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
  mesh_contacts_.for_each_contact([&](int i, const MeshContactRecord& rec,
                                      const Eigen::Vector3d& shear) {
    e +=
        hertz_elastic_energy(model_.pair(p.material[i], rec.material), rec.delta, rec.r_eff, shear);
  });
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
  return store_.size() == 0 ? 0.0 : 2.0 * contact_count() / store_.size();
}

// ---- output -----------------------------------------------------------------------------------

void System::write_particles_vtp(const std::string& path) const {
  sync_particles();
  const Particles& p = store_.core();
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
