#pragma once
// Contacts of the spheres with rigid planes (walls): the planes, grouped into walls, their
// per-particle tangential histories (a store array, so they follow the particles), the force
// kernel and the wall totals.
//
// A particle i touches plane k where delta = R - (x - x_k).n_k > 0; the Hertz-Mindlin law with
// R* = R, m* = m (hertz_mindlin()), torque -cr n x F_t (cr = R - delta/2) and rolling
// resistance -mu_r F_n R w/|w|. The force on each plane is summed per block of
// ThreadPartition::block_size particles by the thread that owns the block, then over the blocks in
// a fixed order (reduce()), so the wall totals do not depend on the number of threads.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/contact_model.hpp"
#include "partita/dem/energy_sums.hpp"
#include "partita/dem/packed_particle.hpp"
#include "partita/dem/particle_store.hpp"
#include "partita/dem/plane_wall.hpp"

#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class WallContacts {
 public:
  /// Registers the tangential histories (one per particle and plane) in the store.
  void attach(ParticleStore& store);

  /// A plane (unit normal into the particle side) as a wall of its own; returns the wall id.
  /// Throws Error on a zero or non-finite normal or a non-finite point or velocity.
  int add_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, int material,
                const Eigen::Vector3d& velocity);
  /// The inside of the box [lo, hi], faces selected by bit k of `faces` (-x, +x, -y, +y, -z,
  /// +z); returns the wall id. Throws Error unless lo < hi and some face is selected.
  int add_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int material, unsigned faces);
  /// Translation velocity of every plane of a wall; throws Error on an unknown wall id.
  void set_velocity(int wall, const Eigen::Vector3d& velocity);
  /// Moves the planes by dt times their velocities.
  void advance(double dt) {
    for (PlaneWall& w : planes_) w.point += dt * w.velocity;
  }

  int wall_count() const { return wall_count_; }
  const std::vector<PlaneWall>& planes() const { return planes_; }
  /// The force the particles exerted on a wall in the last force pass; throws Error on an
  /// unknown id.
  Eigen::Vector3d wall_force(int wall) const;
  /// The part of wall_force(wall) on face `face` of a box wall (0..5: -x, +x, -y, +y, -z, +z, as
  /// add_box()); std::nullopt when the wall has no plane of that normal (an open face). For box
  /// walls (a plane wall's only plane is face k when its normal is that axis direction).
  /// Not part of the saved state: zero until the first force pass after read().
  std::optional<Eigen::Vector3d> face_force(int wall, int face) const;
  /// The histories (N x planes().size(), particle-major).
  const std::vector<Eigen::Vector3d>& shear(const ParticleStore& store) const {
    return store.array<Eigen::Vector3d>(h_shear_);
  }

  /// Sizes the histories and the block sums for n particles (no allocation when unchanged).
  void resize(ParticleStore& store, std::size_t n);
  /// Sizes the histories alone (one per plane): what resize() does to the store, e.g. before
  /// particles are packed for another system (whose store must have the same widths).
  void size_histories(ParticleStore& store) const { store.set_width(h_shear_, planes_.size()); }
  /// Wall totals from the block sums of n particles (fixed order: blocks, then planes).
  void reduce(std::size_t n);
  /// Adds to work[wall] the work the walls' motion did on the particles in the last pass over a
  /// step dt: -F_plane . v_plane dt per plane (F_plane the particles' force on it, after
  /// reduce()).
  /// The power of the walls' motion on the particles in the last pass, sum -F_plane . v_plane.
  double power() const {
    double p = 0.0;
    for (std::size_t k = 0; k < planes_.size(); ++k)
      p -= plane_force_[k].dot(planes_[k].velocity);
    return p;
  }
  void add_work(double dt, std::vector<double>& work) const {
    for (std::size_t k = 0; k < planes_.size(); ++k)
      work[static_cast<std::size_t>(planes_[k].wall)] -=
          plane_force_[k].dot(planes_[k].velocity) * dt;
  }

  /// What one force pass reads and writes, taken once per pass: raw pointers and the plane
  /// count, which the kernel's loop keeps in registers (a member vector's size would be reloaded
  /// after every store through the pair histories' char flags, which may alias it).
  struct Pass {
    const PlaneWall* planes;
    int np;
    Eigen::Vector3d* shear;        // N x np histories
    Eigen::Vector3d* block_force;  // blocks x np sums
    Eigen::Vector3d* reaction = nullptr;  // N x np reactions of the pass (recording), or null

    /// The sums of block b, zeroed: the kernel adds each plane's reaction there.
    Eigen::Vector3d* start_block(int b) const {
      Eigen::Vector3d* s = block_force + static_cast<std::size_t>(b) * np;
      for (int k = 0; k < np; ++k) s[k].setZero();
      return s;
    }
    /// Forces of the planes near particle i (mass mi, material material_i; bit k of `mask`: plane
    /// k; every plane when there are more than 64) added to f and t, their reactions to `block`;
    /// Load: the largest contact load F_n (E*/R)^2 into load. Energy: the dissipative parts
    /// into sums and wd (see energy_sums.hpp).
    template <bool Load, bool Energy = false>
    PARTITA_DEM_INLINE void add_forces(int i, const PackedParticle& qi, const double& mi,
                                       const int& material_i, std::uint64_t mask,
                                       const ContactModel& model, double dt, bool update_history,
                                       Eigen::Vector3d& f, Eigen::Vector3d& t, double& load,
                                       Eigen::Vector3d* block, DissipationSums* sums = nullptr,
                                       WallDissipation* wd = nullptr) const;
  };
  Pass pass(ParticleStore& store) {
    return Pass{planes_.data(), static_cast<int>(planes_.size()),
                store.array<Eigen::Vector3d>(h_shear_).data(), block_force_.data(),
                record_ && reaction_.size() == store.size() * planes_.size() ? reaction_.data()
                                                                            : nullptr};
  }
  /// Whether each force pass records each particle's reaction on the planes near it (off by
  /// default): reactions()[i * planes + k], the force particle i exerted on plane k (zero
  /// without contact), the terms of the plane's total, for sums in an order of one's own (a split
  /// bed's, SubdomainStepper::wall_force()). A pass writes the entries of the planes in the
  /// particle's plane mask (NeighborList::plane_mask(); every plane where there are more than
  /// 64), the only ones that can hold a force; the others keep what an earlier pass left there
  /// (System::for_each_wall_reaction() visits the written ones). Sized, and zeroed, by resize()
  /// (a pass before it records nothing).
  void set_recording(bool on) { record_ = on; }
  bool recording() const { return record_; }
  const std::vector<Eigen::Vector3d>& reactions() const { return reaction_; }

  /// The planes (positions move) / the wall totals, for System's state.
  void write(BinaryWriter& out) const;
  void read(BinaryReader& in);
  void write_forces(BinaryWriter& out) const;
  void read_forces(BinaryReader& in);

 private:
  std::vector<PlaneWall> planes_;
  int wall_count_ = 0;
  int h_shear_ = -1;                          // store array: N x planes tangential histories
  std::vector<Eigen::Vector3d> block_force_;  // blocks x planes
  std::vector<Eigen::Vector3d> wall_force_;   // per wall
  std::vector<Eigen::Vector3d> plane_force_;  // per plane: reduce()'s sums over the blocks
  bool record_ = false;
  std::vector<Eigen::Vector3d> reaction_;  // N x planes (record_)
};

template <bool Load, bool Energy>
PARTITA_DEM_INLINE void WallContacts::Pass::add_forces(
    int i, const PackedParticle& qi, const double& mi, const int& material_i, std::uint64_t mask,
    const ContactModel& model, double dt, bool update_history, Eigen::Vector3d& f,
    Eigen::Vector3d& t, double& load, Eigen::Vector3d* block, DissipationSums* sums,
    WallDissipation* wd) const {
  const double ri = qi.r;
  // (recording: only the planes near i are written, those a reader visits; zeroing every
  // plane's entry of every particle would stream N x planes x 24 bytes through each pass)
  Eigen::Vector3d* const react = reaction ? reaction + static_cast<std::size_t>(i) * np : nullptr;
  for (int k = 0; k < np; ++k) {
    if (np <= 64) {  // jump to the next plane near i
      if (mask == 0) break;
      k = std::countr_zero(mask);
      mask &= mask - 1;
    }
    const PlaneWall& w = planes[k];
    Eigen::Vector3d& sh = shear[static_cast<std::size_t>(i) * np + k];
    const double delta = ri - (qi.x - w.point).dot(w.normal);
    if (delta <= 0.0) {
      sh.setZero();
      if (react) react[k].setZero();
      continue;
    }
    const PairParameters& pp = model.pair(material_i, w.material);
    const double cr = ri - 0.5 * delta;
    Eigen::Vector3d fw, ft;
    DissipativeParts parts;
    const double fn = hertz_mindlin(pp, delta, ri, mi, w.normal, qi.v - w.velocity, cr * qi.w, sh,
                                    dt, update_history, fw, ft, Energy ? &parts : nullptr);
    f += fw;
    t -= cr * w.normal.cross(ft);
    if constexpr (Energy) add_wall_parts(parts, w.normal, cr, w.velocity, *sums, *wd);
    if (pp.rolling_friction > 0.0) {
      const double wn = qi.w.norm();
      if (wn > 0.0) {
        const Eigen::Vector3d tr = (pp.rolling_friction * std::abs(fn) * ri / wn) * qi.w;
        t -= tr;
        if constexpr (Energy) sums->td -= tr;
      }
    }
    if constexpr (Load) {  // wall: R* = R
      const double kw = pp.e_star / ri;
      load = std::max(load, fn * kw * kw);
    }
    block[k] -= fw;
    if (react) react[k] = -fw;
  }
}

}  // namespace partita::dem
