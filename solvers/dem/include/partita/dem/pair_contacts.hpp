#pragma once
// Contacts between two spheres: the per-pair state and the force kernel of one listed pair
// (Hertz-Mindlin with the tangential history, torques, rolling resistance and the contact load of
// the breakage criterion).
//
// PairContacts owns the per-pair state, one entry per slot of the neighbour list's half list
// (slot s: the pair (i, nl.neighbors_[s])): the tangential spring (shear) and whether the spheres
// overlapped in the last force pass (touching). The neighbour list owns the slots; after each of
// its build() and renumber() calls follow(lists.slot_sources()) moves every history to its
// pair's new slot (a pair whose order flipped keeps its history with the sign changed; a new pair
// starts at zero) and marks every slot touching, so that the next force pass settles forces and
// histories. No allocation once sized. The material-pair parameters live in the ContactModel's
// table. The kernel is inline: the force pass keeps the compiler's whole view of the loop.
//
// Histories that travel (particles moved to another System, another subdomain's): pack() writes
// the histories of the pairs of chosen particles as records keyed by particle ids (id_i, id_j,
// the spring of i relative to j, touching); the receiver keeps them waiting (add_waiting()) until
// its next list build, and place_waiting() then puts each one into the slot of its pair (the
// sign changed where the receiver numbers the two the other way round, as follow() does). A
// record whose pair the build did not list is dropped: the two spheres are then further apart
// than the cut-off, and the force pass would have settled (zeroed) that history anyway. A slot
// whose pair the build carried over from the receiver's own previous build keeps that history.
// The contact law keeps no other per-pair state (rolling resistance is a torque of the moment,
// mu_r F_n R* w/|w|, without a spring), so the record is all a pair carries.
//
// Pairs that yield (particles below the comminution limit with breakage's below_limit: yield,
// StepHook::contact_yield()): each slot also holds the pair's permanent overlap (a float,
// yield_overlap()); it follows the slots, travels in the records and is written with the
// histories. Without yielding particles that array is empty (no memory, no work).

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/contact_model.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/packed_particle.hpp"
#include "partita/dem/particles.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace partita::dem {

class PairContacts {
 public:
  /// Moves the per-pair state to the slots of the neighbour list's last build() or renumber()
  /// (sources[k]: where slot k's pair was); every slot is marked touching.
  void follow(const std::vector<NeighborList::SlotSource>& sources);
  std::size_t slot_count() const { return shear_.size(); }
  /// The tangential history of the pair in slot s.
  const Eigen::Vector3d& shear(std::size_t s) const { return shear_[s]; }
  /// Keeps a permanent overlap per slot from now on (zero for every slot; follow() sizes it).
  void keep_plastic();
  bool keeps_plastic() const { return keep_plastic_; }
  /// The permanent overlap of the pair in slot s [m] (0 without yielding particles).
  double plastic(std::size_t s) const { return plastic_.empty() ? 0.0 : plastic_[s]; }

  /// What one force pass reads and writes, taken once per pass (raw pointers the loops keep in
  /// registers: a member vector's data pointer would be reloaded after every store through the
  /// char flags, which may alias it).
  struct Pass {
    Eigen::Vector3d* shear;
    char* touching;
    float* plastic;       // per slot: the permanent overlap, or nullptr (no particle yields)
    const double* mass;   // the store's masses
    const int* material;  // the store's material ids

    /// The kernel (force()) for the pair (i, j) in slot s.
    template <bool Load>
    PARTITA_DEM_INLINE bool force(int s, const ContactModel& model, int i, const PackedParticle& qi,
                                  int j, const PackedParticle& qj, double dt, bool update_history,
                                  Eigen::Vector3d& fij, Eigen::Vector3d& ti, Eigen::Vector3d& tj,
                                  double& load) const {
      return PairContacts::force<Load>(model, qi, qj, mass[i], mass[j], material[i], material[j],
                                       shear[s], touching[s], dt, update_history, fij, ti, tj,
                                       load);
    }
  };
  Pass pass(const Particles& p) {
    return Pass{shear_.data(), touching_.data(), plastic_.empty() ? nullptr : plastic_.data(),
                p.mass.data(), p.material.data()};
  }

  /// A pair's history keyed by particle ids: the tangential spring of particle id_i relative to
  /// id_j, the touching flag and the permanent overlap; packed as 45 bytes (two int64, three
  /// doubles, one byte, one float).
  struct Record {
    std::int64_t id_i = -1, id_j = -1;
    Eigen::Vector3d shear = Eigen::Vector3d::Zero();
    char touching = 0;
    float plastic = 0.0f;
  };
  static constexpr std::size_t record_bytes =
      2 * sizeof(std::int64_t) + 3 * sizeof(double) + 1 + sizeof(float);
  /// Appends to `out` the records of the listed pairs (lists `nl`, the slots this object
  /// follows) that have a history (a nonzero spring or permanent overlap: a pair without one is
  /// what the receiver's build starts a new pair with) and a chosen particle (chosen[i] != 0), then the waiting
  /// records that name an id in `chosen_ids` (sorted); returns how many it appended.
  std::size_t pack(const NeighborList& nl, const std::vector<std::int64_t>& id,
                   const std::vector<char>& chosen, const std::vector<std::int64_t>& chosen_ids,
                   std::vector<std::byte>& out) const;
  /// Reads `count` packed records at `data`; throws Error (nothing changed) when one has a
  /// negative id, two equal ids, a spring that is not finite or a negative permanent overlap.
  static void check_packed(const std::byte* data, std::size_t count);
  /// Adds `count` packed records (checked) to the waiting ones.
  void add_waiting(const std::byte* data, std::size_t count);
  std::size_t waiting_count() const { return waiting_.size(); }
  void clear_waiting() { waiting_.clear(); }
  /// After the lists' build() and follow(): every waiting record into the slot of its pair
  /// (particles by id; dropped when a particle is missing or the pair is not listed, kept out
  /// where the slot's history came from the previous build); the waiting list is emptied. No
  /// allocation once the scratch has had the particle count.
  void place_waiting(const NeighborList& nl, const std::vector<std::int64_t>& id);

  /// Writes / reads the histories, flags and permanent overlaps (in the state format, between the
  /// neighbour list's rows and its build references: see System::write_body()). read() throws
  /// Error when their number is not `slots` (the neighbour list's pair count); with_plastic
  /// false: a state without permanent overlaps (format version 4), read as none.
  void write(BinaryWriter& out) const;
  void read(BinaryReader& in, std::size_t slots, bool with_plastic = true);

  /// Force of the pair (i, j) on i and the torques on i and j (masses mi, mj and materials of the
  /// two, read only when they overlap); false (and the history settled:
  /// zeroed once the spheres part) when they do not overlap. Torques T_i = -cr_i n x F_t,
  /// T_j = -cr_j n x F_t (cr = R - delta/2, LIGGGHTS convention), rolling resistance
  /// T_i = -mu_r F_n R* w_rel/|w_rel| = -T_j (w_rel = omega_i - omega_j).
  /// Load: also the contact load F_n (E*/R*)^2 (breakage criterion, System::contact_load()).
  /// plastic: the pair's permanent overlap (nullptr: none), the contact yielding at the pair's
  /// yield pressure p_y > 0 (yield_overlap(); its growth kept when update_history, its work added
  /// to *plastic_work). The geometric overlap gives the arms cr, the elastic one the force.
  template <bool Load>
  static PARTITA_DEM_INLINE bool force(const ContactModel& model, const PackedParticle& qi,
                                       const PackedParticle& qj, const double& mi, const double& mj,
                                       const int& material_i, const int& material_j,
                                       Eigen::Vector3d& shear, char& touching, double dt,
                                       bool update_history, Eigen::Vector3d& fij,
                                       Eigen::Vector3d& ti, Eigen::Vector3d& tj, double& load,
                                       float* plastic = nullptr, double p_y = 0.0,
                                       double* plastic_work = nullptr) {
    const Eigen::Vector3d d = qi.x - qj.x;
    const double ri = qi.r, rj = qj.r;
    const double rsum = ri + rj;
    const double r2 = d.squaredNorm();
    if (r2 >= rsum * rsum) {
      if (touching) {
        touching = 0;
        shear.setZero();
        if (plastic != nullptr) *plastic = 0.0f;
      }
      return false;
    }
    touching = 1;
    const double r = std::sqrt(r2);
    const Eigen::Vector3d nrm =
        r > 0.0 ? Eigen::Vector3d(d * (1.0 / r)) : Eigen::Vector3d::UnitZ();
    const double delta_geometric = rsum - r;
    const PairParameters& pp = model.pair(material_i, material_j);
    const double r_eff = ri * rj / rsum;
    const double m_eff = mi * mj / (mi + mj);
    const double cri = ri - 0.5 * delta_geometric, crj = rj - 0.5 * delta_geometric;
    const Eigen::Vector3d w_arm = cri * qi.w + crj * qj.w;
    double delta = delta_geometric;
    if (plastic != nullptr) {
      float kept = *plastic;
      delta = yield_overlap(delta_geometric, r_eff, pp.e_star, p_y, kept,
                            update_history ? plastic_work : nullptr);
      if (update_history) *plastic = kept;
    }
    Eigen::Vector3d ft;
    const double fn = hertz_mindlin(pp, delta, r_eff, m_eff, nrm, qi.v - qj.v, w_arm, shear, dt,
                                    update_history, fij, ft);
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

 private:
  std::vector<Eigen::Vector3d> shear_;  // per slot: tangential spring
  std::vector<char> touching_;          // per slot: overlap > 0 in the last force pass
  std::vector<float> plastic_;          // per slot: permanent overlap (keep_plastic_) or empty
  bool keep_plastic_ = false;
  std::vector<float> new_plastic_;      // scratch of follow()
  std::vector<Eigen::Vector3d> new_shear_;  // scratch of follow()
  std::vector<Record> waiting_;             // records received, until the next build
  std::vector<std::pair<std::int64_t, int>> index_of_id_;  // scratch of place_waiting()
};

}  // namespace partita::dem
