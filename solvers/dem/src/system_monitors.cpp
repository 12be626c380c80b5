// System: monitors (energies, forces, contact counts).
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"

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

}  // namespace partita::dem
