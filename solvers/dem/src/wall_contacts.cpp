#include "partita/dem/wall_contacts.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/thread_partition.hpp"

#include <sstream>

namespace partita::dem {

void WallContacts::attach(ParticleStore& store) {
  h_shear_ = store.add_array<Eigen::Vector3d>("plane_shear", 0, Eigen::Vector3d::Zero());
}

int WallContacts::add_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                            int material, const Eigen::Vector3d& velocity) {
  if (!(normal.norm() > 0.0) || !normal.allFinite() || !point.allFinite() ||
      !velocity.allFinite()) {
    throw Error("add_plane: need a finite point and velocity and a non-zero normal, got point " +
                vector_text(point) + ", normal " + vector_text(normal));
  }
  PlaneWall plane;
  plane.point = point;
  plane.normal = normal.normalized();
  plane.velocity = velocity;
  plane.material = material;
  plane.wall = wall_count_;
  planes_.push_back(plane);
  wall_force_.assign(wall_count_ + 1, Eigen::Vector3d::Zero());
  return wall_count_++;
}

int WallContacts::add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material,
                          unsigned faces) {
  if (!((hi - lo).array() > 0.0).all()) {
    throw Error("add_box: need lo < hi in every direction, got lo " + vector_text(lo) + ", hi " +
                vector_text(hi));
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
  return wall;
}

void WallContacts::set_velocity(int wall, const Eigen::Vector3d& velocity) {
  if (wall < 0 || wall >= wall_count_) {
    std::ostringstream msg;
    msg << "set_wall_velocity: unknown wall id " << wall << "; ids are 0.." << wall_count_ - 1;
    throw Error(msg.str());
  }
  for (PlaneWall& p : planes_)
    if (p.wall == wall) p.velocity = velocity;
}

Eigen::Vector3d WallContacts::wall_force(int wall) const {
  if (wall < 0 || wall >= wall_count_) {
    std::ostringstream msg;
    msg << "wall_force: unknown wall id " << wall << "; ids are 0.." << wall_count_ - 1;
    throw Error(msg.str());
  }
  return wall_force_[wall];
}

std::optional<Eigen::Vector3d> WallContacts::face_force(int wall, int face) const {
  (void)wall_force(wall);  // throws on an unknown id
  if (face < 0 || face > 5) {
    std::ostringstream msg;
    msg << "face_force: unknown face " << face << "; faces are 0..5 (-x, +x, -y, +y, -z, +z)";
    throw Error(msg.str());
  }
  // a box's face k is the plane of its wall with the normal +e_axis (k even) or -e_axis (k odd)
  // (add_box() sets these normals exactly)
  const int axis = face / 2;
  const double sign = face % 2 == 0 ? 1.0 : -1.0;
  for (std::size_t k = 0; k < planes_.size(); ++k) {
    const PlaneWall& p = planes_[k];
    if (p.wall != wall || p.normal[axis] != sign) continue;
    return k < plane_force_.size() ? plane_force_[k] : Eigen::Vector3d::Zero();
  }
  return std::nullopt;
}

void WallContacts::resize(ParticleStore& store, std::size_t n) {
  const std::size_t np = planes_.size();
  store.set_width(h_shear_, np);
  block_force_.assign(((n + ThreadPartition::block_size - 1) / ThreadPartition::block_size) * np,
                      Eigen::Vector3d::Zero());
  wall_force_.resize(wall_count_, Eigen::Vector3d::Zero());
  if (record_) reaction_.assign(n * np, Eigen::Vector3d::Zero());
}

// Each plane's total over the blocks in block order, then each wall's over its planes in plane
// order: a fixed order whatever the number of threads. The planes' sums are independent chains
// (one chain per wall would take 2-3 us a step for the 313 blocks of the
// 20,001-particle peer bed, serial between the parallel force passes).
void WallContacts::reduce(std::size_t n) {
  const std::size_t np = planes_.size();
  const std::size_t blocks = (n + ThreadPartition::block_size - 1) / ThreadPartition::block_size;
  plane_force_.assign(np, Eigen::Vector3d::Zero());  // (no allocation once sized)
  Eigen::Vector3d* const sum = plane_force_.data();
  const Eigen::Vector3d* block = block_force_.data();
  for (std::size_t b = 0; b < blocks; ++b, block += np)
    for (std::size_t k = 0; k < np; ++k) sum[k] += block[k];
  for (Eigen::Vector3d& w : wall_force_) w.setZero();
  for (std::size_t k = 0; k < np; ++k) wall_force_[planes_[k].wall] += sum[k];
}

void WallContacts::write(BinaryWriter& out) const { out.array(planes_); }

void WallContacts::read(BinaryReader& in) { in.array(planes_, "the planes"); }

void WallContacts::write_forces(BinaryWriter& out) const { out.array(wall_force_); }

void WallContacts::read_forces(BinaryReader& in) { in.array(wall_force_, "the wall forces"); }

}  // namespace partita::dem
