#pragma once
// Contacts of a sphere with the triangle meshes (faces, edges, vertices, each counted once), their
// tangential histories carried from feature to feature, and the reduction of the contact forces to
// the meshes' triangles and vertices.
//
// Storage in proportion to use: only particles that have mesh candidates at the last neighbour
// list build (those within R + skin of a triangle: the only ones that can touch a mesh until the
// next build) have a row, with room for min(max_contacts, candidates) contacts (more if it held
// more before the build). A row holds the contacts of the last force pass (feature key,
// tangential history, record). Rows are laid out again after each build (follow_build(): a
// particle keeps its contacts, particles without candidates lose theirs, as the next pass would
// drop them) and follow the particles through renumbering and removal (renumber()); save/restore
// writes them. No meshes: no rows, nothing per particle. No allocation once sized: the arrays
// and their scratch are swapped, and a buffer that must grow gets half as much room again.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/contact_model.hpp"
#include "partita/dem/energy_sums.hpp"
#include "partita/dem/mesh_contact_record.hpp"
#include "partita/dem/neighbor_list.hpp"
#include "partita/dem/particles.hpp"
#include "partita/dem/triangle_mesh.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class MeshContacts {
 public:
  /// Contacts one particle keeps with mesh features at a time; further ones are ignored.
  static constexpr int max_contacts = 8;

  struct Particle {  ///< what the contact law reads about the sphere
    const Eigen::Vector3d& x;
    double r;
    const Eigen::Vector3d& v;
    double m;
    const Eigen::Vector3d& w;
    int material;
    /// > 0: the particle yields at this mean contact pressure [Pa] (StepHook::contact_yield())
    double yield_pressure = 0.0;
    /// true: the System's first force pass (every contact found without history, none made by
    /// motion): a centre found inside a one-sided body is pushed out with its whole overlap
    bool first_pass = false;
  };
  /// One particle's row: its contacts of the last pass (count), their feature keys, tangential
  /// histories and records, room for `capacity`.
  struct Row {
    int& count;
    int capacity;
    std::int64_t* key;
    Eigen::Vector3d* shear;
    MeshContactRecord* records;
  };
  /// What one force pass reads and writes, taken once per pass (raw pointers).
  struct Pass {
    const int* particle;  // per row: its particle (ascending)
    const int* slot;      // per row: its first slot (rows + 1 entries)
    int* count;
    std::int64_t* key;
    Eigen::Vector3d* shear;
    MeshContactRecord* records;
    int rows;

    /// The first row whose particle is >= i.
    int first_row(int i) const {
      return static_cast<int>(std::lower_bound(particle, particle + rows, i) - particle);
    }
    Row row(int r) const {
      const int s = slot[r];
      return Row{count[r], slot[r + 1] - s, key + s, shear + s, records + s};
    }
  };
  Pass pass() {
    return Pass{particle_.data(),
                slot_.data(),
                count_.data(),
                key_.data(),
                shear_.data(),
                record_.data(),
                static_cast<int>(particle_.size())};
  }

  /// Lays the rows out for the candidates of the neighbour list's last build(), keeping each
  /// particle's contacts.
  void follow_build(const NeighborList& lists);
  /// After the particles were renumbered or removed (old particle i is now new_of_old[i], < 0:
  /// removed): the rows follow their particles (removed ones are dropped).
  void renumber(const std::vector<int>& new_of_old);
  /// Rows (particles that may touch a mesh) and contacts of the last pass.
  std::size_t row_count() const { return particle_.size(); }
  std::size_t contact_count() const;
  /// Calls visit(i, record, shear) for every contact of the last pass, particles in order.
  template <class Visit>
  void for_each_contact(Visit&& visit) const {
    for (std::size_t r = 0; r < particle_.size(); ++r)
      for (int c = 0; c < count_[r]; ++c) {
        const std::size_t s = static_cast<std::size_t>(slot_[r] + c);
        visit(particle_[r], record_[s], shear_[s]);
      }
  }

  /// Calls visit(i, record) for every contact the particles would have with the meshes at their
  /// present positions, found as the force pass finds them (evaluate(): features counted once),
  /// from the candidates of `lists` (built for these positions, e.g. a scratch search()), without
  /// tangential histories and without storing anything; particles in order. For the contacts
  /// before the first force pass (System::elastic_energy()), when the rows hold none yet.
  template <class Visit>
  static void for_each_contact_now(const Particles& p, const NeighborList& lists,
                                   const std::vector<TriangleMesh>& meshes,
                                   const ContactModel& model, Visit&& visit) {
    if (meshes.empty()) return;
    const int n = static_cast<int>(p.size());
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      if (lists.mesh_offsets_[i + 1] == lists.mesh_offsets_[i]) continue;
      int count = 0;
      std::int64_t key[max_contacts];
      Eigen::Vector3d shear[max_contacts];
      MeshContactRecord records[max_contacts];
      const Row row{count, max_contacts, key, shear, records};
      const Particle q{p.position[i], p.radius[i], zero, p.mass[i], zero, p.material[i], 0.0, true};
      Eigen::Vector3d f = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
      double load = 0.0;
      evaluate<false>(i, q, lists, meshes, model, row, 0.0, false, f, t, load);
      for (int c = 0; c < count; ++c) visit(i, records[c]);
    }
  }

  /// Adds the mesh contact forces and torques of particle i (candidates from `lists`) to f and t,
  /// updates its row; Load: also the largest F_n (E*/R*)^2 into load (R* = R); Energy: the
  /// dissipative parts into sums and wd (energy_sums.hpp).
  template <bool Load, bool Energy = false>
  static void evaluate(int i, const Particle& q, const NeighborList& lists,
                       const std::vector<TriangleMesh>& meshes, const ContactModel& model,
                       const Row& row, double dt, bool update_history, Eigen::Vector3d& f,
                       Eigen::Vector3d& t, double& load, DissipationSums* sums = nullptr,
                       WallDissipation* wd = nullptr);
  /// The meshes' triangle and vertex forces from the contacts of the last pass.
  void reduce(std::vector<TriangleMesh>& meshes) const;

  /// A particle's contacts as bytes, to move it to another System (another subdomain): pack()
  /// appends, for each particle of `which` in order, its contact count (int32) and that many
  /// contacts (feature key, tangential history, record: packed_contact_bytes each; a particle
  /// without a row has none). check_packed() reads such bytes for n particles against the
  /// receiver's meshes and returns how many bytes they take; it throws Error when they do not
  /// fit (a count above max_contacts, a mesh or triangle the receiver does not have, bytes
  /// missing). unpack() appends rows for the particles first, first + 1, ... (the receiver's
  /// newest, so the rows stay in particle order) from checked bytes; the next follow_build()
  /// keeps them as it keeps every particle's contacts.
  static constexpr std::size_t packed_contact_bytes =
      sizeof(std::int64_t) + 3 * sizeof(double) + sizeof(MeshContactRecord);
  void pack(const std::vector<int>& which, std::vector<std::byte>& out) const;
  static std::size_t check_packed(const std::byte* data, std::size_t bytes, std::size_t n,
                                  const std::vector<TriangleMesh>& meshes);
  void unpack(int first, std::size_t n, const std::byte* data);

  /// Writes / reads the rows (System's state). read() throws Error when they are inconsistent
  /// or name a particle >= `particles`.
  void write(BinaryWriter& out) const;
  void read(BinaryReader& in, std::size_t particles);

 private:
  // lays out new_* for rows (particle, capacity), copies each kept row's contacts from row
  // `from` (-1: none), then swaps them in
  void start_layout(std::size_t rows, std::size_t slots);
  void add_row(int particle, int capacity, int from);
  void finish_layout();

  std::vector<int> particle_;              // per row
  std::vector<int> slot_{0};               // per row: first slot; rows + 1
  std::vector<int> count_;                 // per row: contacts of the last pass
  std::vector<std::int64_t> key_;          // per slot: feature key
  std::vector<Eigen::Vector3d> shear_;     // per slot: tangential history
  std::vector<MeshContactRecord> record_;  // per slot: result of the last pass
  // scratch (swapped with the arrays above)
  std::vector<int> new_particle_, new_slot_, new_count_;
  std::vector<std::int64_t> new_key_;
  std::vector<Eigen::Vector3d> new_shear_;
  std::vector<MeshContactRecord> new_record_;
  std::vector<std::pair<int, int>> order_;  // renumber(): (new particle, old row)
};

}  // namespace partita::dem
