#pragma once
// Neighbour search: linked cells + Verlet lists with a skin.
//
// Particle pairs: a half list in compressed rows (pairs (i, j) with j > i, j ascending), cut-off
// R_i + R_j + skin, so that it stays valid until some particle has moved more than skin/2 since
// the build. The per-pair state (tangential histories, contact flags) is not kept here: its owner
// (PairContacts) holds one entry per slot and follows the slot mapping that build() and
// renumber() leave in slot_sources().
// Particle-triangle candidates: triangles are binned into the same cells (box grown by
// R_max + skin), each particle keeps the triangles within R + skin; valid until a particle or a
// mesh vertex has moved more than skin/2.
// Planes: each particle keeps a bit mask of the planes within R + skin (up to 64 planes; more
// are all checked every step); valid until a particle or plane has moved more than skin/2.
// Cells are 2 R_max + skin wide (correct for any size distribution; with very wide ones the
// cells hold many small particles). Vectors are reused: no allocation between rebuilds.
// The grid has at most 4 N + 64 cells (memory in proportion to the particles, whatever their
// extent); a sparser cloud gets wider cells. When that leaves a large set of particles in a
// handful of cells (a bed and one particle hundreds of metres away: the search would compare
// nearly every pair), or a position is infinite, build() throws Error naming the particle.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/particles.hpp"
#include "partita/dem/plane_wall.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

struct MeshCandidate {
  int mesh = 0;
  int triangle = 0;
};

class NeighborList {
 public:
  /// Where the pair in a slot was before the last build() or renumber(): its old slot (-1: the
  /// pair was not listed) and whether its order (i < j) flipped, so that a history of i relative
  /// to j changes sign.
  struct SlotSource {
    int slot = -1;
    bool flipped = false;
  };

  void set_skin(double skin) { skin_ = skin; }
  double skin() const { return skin_; }
  /// Passive particles for the builds that follow (null: none): no pair between two passive
  /// particles is listed, and a passive particle gets no plane and no mesh candidates. A split
  /// bed's ghosts (System::phase_build()): their own forces are not used, only their pairs with
  /// the particles the subdomain owns. The flags (one per particle) must live through the build.
  void set_passive(const std::vector<char>* passive) { passive_ = passive; }
  /// Forgets the lists (next needs_rebuild() is true); slot_sources() becomes empty (per-pair
  /// state is dropped by the owner's follow()).
  void clear();
  /// True when a particle or mesh vertex moved more than skin/2 since the last build.
  bool needs_rebuild(const Particles& particles, const std::vector<PlaneWall>& planes,
                     const std::vector<TriangleMesh>& meshes) const;
  /// Same, given the largest squared particle displacement since the build (computed by the
  /// caller's integration loop).
  bool needs_rebuild(double max_moved2, const std::vector<PlaneWall>& planes,
                     const std::vector<TriangleMesh>& meshes) const;
  /// Rebuilds cells and lists; slot_sources() maps each new slot to the pair's old slot (pairs
  /// of the previous build that are still listed).
  void build(const Particles& particles, const std::vector<PlaneWall>& planes,
             std::vector<TriangleMesh>& meshes);
  /// The same lists for the current positions without marking the meshes' positions at the
  /// build (build() = search() + that mark): for a scratch list that looks at the contacts of
  /// the moment and leaves the meshes as they are (System::elastic_energy() before the first
  /// step).
  void search(const Particles& particles, const std::vector<PlaneWall>& planes,
              const std::vector<TriangleMesh>& meshes);
  /// After the caller renumbered the particles (old index i is now new_of_old[i]): rewrites the
  /// pair rows in the new numbering (slot_sources(): a pair's old slot and whether its order
  /// flipped), so that the next build() finds the pairs again. The lists must be rebuilt before
  /// they are used again.
  void renumber(const std::vector<int>& new_of_old);
  /// Same, where new_of_old[i] < 0 marks a removed particle (its pairs are dropped) and `new_count` is the number of particles after the change.
  void renumber(const std::vector<int>& new_of_old, int new_count);
  /// A particle born inside another at run time (a fragment): the index of the particle it
  /// replaces (before the change) and its centre relative to that particle's centre.
  struct Offspring {
    int parent = 0;
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  };
  /// Takes in a change of the particle set without a search: the particles with
  /// new_of_old[i] < 0 are gone, the others keep their order (new_of_old ascending, `kept` of
  /// them), and born.size() particles were appended (indices kept, kept + 1, ...; `p` is the set
  /// after the change), each lying inside the particle it replaces (|offset| + R_new <= R_parent,
  /// the parent among those gone). A newborn's reference position is its parent's at the build
  /// plus its offset, so its displacement since the build is its parent's; every particle within
  /// R_new + R_j + skin of that reference was within R_parent + R_j + skin of the parent's, so
  /// its pairs are found among the parent's listed neighbours (and the newborns of neighbouring
  /// parents) and the lists stay valid until the usual displacement test says otherwise. Its
  /// planes and mesh candidates are its parent's. Each row stays ascending; the pairs already
  /// listed keep their slot sources (slot_sources()), the new ones have none. Requires lists
  /// built for the set before the change (built(), one row per particle); throws Error if not.
  void insert_offspring(const std::vector<int>& new_of_old, int kept,
                        const std::vector<Offspring>& born, const Particles& p);
  /// The listed neighbours of each particle in `which` (distinct indices with rows), both
  /// halves, ascending: those of which[k] are items[offsets[k] .. offsets[k + 1]). One pass over
  /// the pairs, on the threads. While the lists are valid every particle touching one of them is
  /// among them.
  void listed_neighbours(const std::vector<std::size_t>& which, std::vector<int>& offsets,
                         std::vector<int>& items) const;
  /// The listed pairs with a particle flagged in `in` (one flag per row), as (row i, slot s): the
  /// pair (i, neighbors()[s]). In the list's order (rows ascending, each row's slots ascending)
  /// whatever the number of threads; one pass over the pairs, on the threads.
  void slots_touching(const std::vector<char>& in, std::vector<std::pair<int, int>>& out) const;
  /// The mesh triangles listed near particle i (within R + skin at the build): [first, last).
  const MeshCandidate* mesh_candidates_begin(std::size_t i) const {
    return mesh_candidates_.data() + (mesh_offsets_.size() > i + 1 ? mesh_offsets_[i] : 0);
  }
  const MeshCandidate* mesh_candidates_end(std::size_t i) const {
    return mesh_candidates_.data() + (mesh_offsets_.size() > i + 1 ? mesh_offsets_[i + 1] : 0);
  }
  /// Whether the lists were built for the current particles (cleared by renumber()).
  bool built() const { return valid_ && !position_at_build_.empty(); }
  /// The slot mapping of the last build() or renumber() (one entry per slot; empty after
  /// clear()). The owner of per-pair state follows it before the next build() or renumber().
  const std::vector<SlotSource>& slot_sources() const { return slot_source_; }
  /// Writes / reads the lists in two parts, the rows (skin, build count, validity, offsets,
  /// neighbours) and the build references (positions and planes at the build, plane masks, mesh
  /// candidates); the state format has the pairs' histories between them (System). The cell
  /// grid is scratch of build() and not part of the state. read_rows() throws Error when the
  /// offsets and neighbours do not agree.
  void write_rows(BinaryWriter& out) const;
  void write_build_references(BinaryWriter& out) const;
  void read_rows(BinaryReader& in);
  void read_build_references(BinaryReader& in);
  /// Planes near particle i (bit k: plane k); all bits set when there are more than 64 planes.
  std::uint64_t plane_mask(std::size_t i) const { return plane_mask_[i]; }

  std::size_t pair_count() const { return neighbors_.size(); }
  /// Calls visit(i, j) for every listed pair (i < j): rows in order, each row ascending.
  template <class Visit>
  void for_each_pair(Visit&& visit) const {
    for (std::size_t i = 0; i + 1 < offsets_.size(); ++i)
      for (int s = offsets_[i]; s < offsets_[i + 1]; ++s) visit(static_cast<int>(i), neighbors_[s]);
  }
  long build_count() const { return builds_; }

 private:
  friend class System;
  friend class ThreadPartition;
  friend class MeshContacts;
  friend class PairContacts;

  struct Grid {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    double inv_cell = 1.0;
    int nx = 1, ny = 1, nz = 1;
    int coord(double x, double o, int n) const;
    std::array<int, 3> coords(const Eigen::Vector3d& x) const;
    int index(int ix, int iy, int iz) const { return (iz * ny + iy) * nx + ix; }
    int cells() const { return nx * ny * nz; }
  };

  template <class Visit>
  void visit_pairs(const Particles& p, int i, Visit&& visit) const;
  /// Throws Error naming the particle that makes the extent [lo, hi] absurd (non-finite, or so
  /// far from the others that the capped grid degenerates; cell: the grown cell, 0 if none).
  [[noreturn]] static void throw_absurd_extent(const Particles& p, const Eigen::Vector3d& lo,
                                               const Eigen::Vector3d& hi, double natural,
                                               double cell);
  // A grid grown by the cap is degenerate when the search would visit more than
  // kDegenerateVisits candidates per particle (sum over the cells of n_c^2, over N; a dense bed
  // at the natural cell: 1 to 10; a grain-size ratio of 10: about 1,500); below
  // kDegenerateMinParticles an all-pairs search is cheap anyway.
  static constexpr double kDegenerateVisits = 4096.0;
  static constexpr int kDegenerateMinParticles = 8192;
  void build_mesh_candidates(const Particles& p, const std::vector<TriangleMesh>& meshes,
                             double r_max);

  double skin_ = 0.0;
  const std::vector<char>* passive_ = nullptr;  // (set_passive())
  long builds_ = 0;
  bool valid_ = false;
  Grid grid_;
  std::vector<int> cell_start_, cell_items_, particle_cell_;
  // half list (compressed rows)
  std::vector<int> offsets_, neighbors_;
  std::vector<SlotSource> slot_source_;  // per slot: where the pair was before the last change
  std::vector<Eigen::Vector3d> position_at_build_;
  std::vector<Eigen::Vector3d> plane_at_build_;
  std::vector<std::uint64_t> plane_mask_;
  // scratch reused between builds
  std::vector<int> new_offsets_, new_neighbors_, counts_;
  // scratch of insert_offspring()
  std::vector<int> parent_of_, parent_nb_offsets_, parent_nb_, born_offsets_, born_items_;
  mutable std::vector<int> mark_, mark_counts_;  // scratch of listed_neighbours()
  mutable std::vector<std::pair<int, int>> touching_;                   // (the same)
  mutable std::vector<std::vector<std::pair<int, int>>> touching_blocks_;  // (scan's blocks)
  std::vector<std::size_t> parent_list_;  // (insert_offspring(): the parents in order)
  std::vector<std::pair<int, int>> added_pairs_;
  std::vector<Eigen::Vector3d> born_reference_;
  std::vector<std::uint64_t> born_mask_;
  std::vector<int> new_mesh_offsets_;
  std::vector<MeshCandidate> new_mesh_candidates_;
  // particle-triangle candidates
  std::vector<int> tri_cell_start_;
  std::vector<MeshCandidate> tri_cell_items_;
  std::vector<int> mesh_offsets_;  // N + 1 (just {0} when there are no meshes)
  std::vector<MeshCandidate> mesh_candidates_;
};

}  // namespace partita::dem
