// System: particles moved to another System set up alike, with everything they carry (the step
// of a DEM spread over subdomains in which a particle changes owner).
//
// One message per destination, all of it raw bytes (both ends have the same byte order and
// types, as for state files):
//   header   magic "PMIG", format version, the store's layout hash, the particle count n, the
//            pair record count m, the mesh section's size in bytes, whether the particles'
//            forces are those of a force pass (System::forces_valid_)
//   store    ParticleStore::pack() of the n particles: every array, so the core values, the
//            forces and torques of the last pass (the first half of the next step uses them),
//            the ids, the plane histories and the hooks' arrays (breakage strengths and load
//            limits) come along without a line here
//   pairs    m records PairContacts::Record: the pairs with a history that have a particle of
//            the message, keyed by particle ids (and the sender's own waiting records of them)
//   meshes   per particle its mesh contacts (MeshContacts::pack())
// The receiver appends the particles at the end (their mesh contacts as rows of its newest
// particles), keeps the pair records waiting until its next list build, which is due at its next
// step (the particle set changed), and places them there (PairContacts::place_waiting()).
//
// Why the pair records wait for the build instead of going into the receiver's lists at once:
// the partner of a moving particle is often not in the receiver when the message arrives (it
// arrives in another message, or is a ghost the next exchange brings); at the build every
// particle of the step is there, and a pair the build does not list is out of reach anyway.
// A pair between two particles of different messages comes in both; both records agree.
//
// Around these two calls, SubdomainStepper (subdomain.hpp) chooses the particles leaving each
// subdomain and its ghosts for the others (DomainDecomposition::owner() and near() of their
// positions) on the steps when the lists are rebuilt, sends each destination its messages
// through a SubdomainTransport, removes the senders' copies and unpacks what arrives before the
// lists are built. With the energy
// accounting on, remove_particles() books the leaving particles' energy as a change of the
// particle set (energies().breakage); summed over the subdomains the receiver's matching change
// is not booked, so a migrating run must sum its energies with that in mind. The ids a System
// hands out to new particles (fragments) must be unique across subdomains (ParticleStore ids are
// unique per store only): that is the MPI layer's, for example an id range per rank.
#include "partita/dem/system.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>

namespace partita::dem {

namespace {

constexpr std::uint32_t message_magic = 0x47494d50u;  // "PMIG"
constexpr std::uint32_t message_version = 1;
// magic, version, layout hash, n, m, mesh bytes, forces flag
constexpr std::size_t header_bytes = 4 + 4 + 8 + 8 + 8 + 8 + 1;

template <class T>
void put(std::byte* at, const T& v) {
  std::memcpy(at, &v, sizeof v);
}
template <class T>
T get(const std::byte* at) {
  T v;
  std::memcpy(&v, at, sizeof v);
  return v;
}

}  // namespace

void System::pack_particles(const std::vector<int>& which, std::vector<std::byte>& out) {
  sync_particles();
  walls_.size_histories(store_);  // (one per plane, as the receiver's)
  const Particles& p = store_.core();
  const std::size_t n = p.size();
  chosen_.assign(n, 0);
  chosen_ids_.clear();
  for (const int i : which) {
    if (i < 0 || static_cast<std::size_t>(i) >= n || chosen_[i]) {
      std::ostringstream msg;
      msg << "pack_particles: particle " << i
          << (i >= 0 && static_cast<std::size_t>(i) < n ? " is named twice" : " does not exist")
          << "; give distinct indices 0.." << static_cast<long>(n) - 1;
      throw Error(msg.str());
    }
    chosen_[i] = 1;
    chosen_ids_.push_back(p.id[i]);
  }
  std::sort(chosen_ids_.begin(), chosen_ids_.end());
  const std::size_t start = out.size();
  out.resize(start + header_bytes);
  store_.pack(which, out);
  const std::size_t records = pairs_.pack(neighbors_, p.id, chosen_, chosen_ids_, out);
  const std::size_t mesh_start = out.size();
  mesh_contacts_.pack(which, out);
  std::byte* h = out.data() + start;
  put(h, message_magic);
  put(h + 4, message_version);
  put(h + 8, store_.layout_hash());
  put(h + 16, static_cast<std::uint64_t>(which.size()));
  put(h + 24, static_cast<std::uint64_t>(records));
  put(h + 32, static_cast<std::uint64_t>(out.size() - mesh_start));
  put(h + 40, static_cast<char>(forces_valid_));
}

std::size_t System::unpack_particles(const std::byte* data, std::size_t bytes) {
  // every check before the first change: a refused message leaves the system as it was
  const auto refuse = [&](const std::string& why) { throw Error("unpack_particles: " + why); };
  if (bytes < header_bytes)
    refuse("the message has " + std::to_string(bytes) + " bytes, less than its " +
           std::to_string(header_bytes) + "-byte header");
  walls_.size_histories(store_);  // (one per plane, as the sender's)
  if (get<std::uint32_t>(data) != message_magic)
    refuse(
        "the bytes are not a particle message (no 'PMIG' at the start); give what "
        "pack_particles() wrote");
  if (const auto v = get<std::uint32_t>(data + 4); v != message_version)
    refuse("the message has format version " + std::to_string(v) + "; this build reads " +
           std::to_string(message_version));
  if (get<std::uint64_t>(data + 8) != store_.layout_hash())
    refuse("the message comes from a system whose particle arrays differ from this one's ('" +
           store_.layout() + "' here): set both up alike (walls, hooks)");
  const auto n = get<std::uint64_t>(data + 16);
  const auto m = get<std::uint64_t>(data + 24);
  const auto mesh_bytes = get<std::uint64_t>(data + 32);
  const bool forces = get<char>(data + 40) != 0;
  const std::size_t row = store_.packed_bytes_per_particle();
  const std::size_t body = bytes - header_bytes;
  if (n > body / row || m > (body - n * row) / PairContacts::record_bytes ||
      mesh_bytes != body - n * row - m * PairContacts::record_bytes)
    refuse("the message's " + std::to_string(bytes) + " bytes do not hold the " +
           std::to_string(n) + " particles, " + std::to_string(m) + " pair histories and " +
           std::to_string(mesh_bytes) +
           " bytes of mesh contacts its header announces (cut short or corrupt)");
  const std::byte* particles = data + header_bytes;
  const std::byte* records = particles + n * row;
  const std::byte* mesh = records + m * PairContacts::record_bytes;
  // ids: >= 0, distinct, none that this system holds already
  store_.packed_ids(particles, n * row, message_ids_);
  for (const std::int64_t id : message_ids_)
    if (id < 0) refuse("the message holds particle id " + std::to_string(id) + " (ids are >= 0)");
  chosen_ids_.assign(store_.core().id.begin(), store_.core().id.end());
  chosen_ids_.insert(chosen_ids_.end(), message_ids_.begin(), message_ids_.end());
  std::sort(chosen_ids_.begin(), chosen_ids_.end());
  if (const auto d = std::adjacent_find(chosen_ids_.begin(), chosen_ids_.end());
      d != chosen_ids_.end())
    refuse("particle id " + std::to_string(*d) +
           " would be here twice (the message holds it twice, or this system holds it "
           "already)");
  try {
    PairContacts::check_packed(records, m);
    if (MeshContacts::check_packed(mesh, mesh_bytes, n, meshes_) != mesh_bytes)
      throw Error("the message has bytes after its particles' mesh contacts (corrupt)");
  } catch (const Error& e) {
    refuse(e.what());
  }

  sync_particles();
  const bool was_empty = store_.size() == 0;
  const std::size_t first = store_.unpack(particles, n * row);
  mesh_contacts_.unpack(static_cast<int>(first), n, mesh);
  pairs_.add_waiting(records, m);
  // the forces stay those of a pass when the particles' are (a receiver that had none takes the
  // sender's word)
  forces_valid_ = (was_empty || forces_valid_) && forces;
  particles_changed();
  return first;
}

}  // namespace partita::dem
