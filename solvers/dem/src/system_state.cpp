// SystemState (the versioned binary form of a System's dynamic state) and System's save, restore,
// write and read of it.
#include "partita/dem/system_state.hpp"

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/system.hpp"

#include <cstring>
#include <sstream>

namespace partita::dem {

namespace {

constexpr char magic[8] = {'P', 'T', 'D', 'E', 'M', 'S', 'T', '1'};
constexpr std::uint32_t byte_order_mark = 0x01020304u;
constexpr std::uint32_t body_tag = 0x424f4459u;  // "BODY": start of a System's body
constexpr std::uint32_t end_tag = 0x454e4421u;   // "END!"

}  // namespace

void SystemState::write(std::ostream& out) const {
  BinaryWriter w(out);
  out.write(magic, sizeof magic);
  w.value(format_version);
  w.value(byte_order_mark);
  w.value(time_);
  w.value(static_cast<std::int64_t>(steps_));
  w.value(static_cast<std::uint64_t>(particles_));
  w.string(body_);
  if (!out) throw Error("write_state: the stream refused the state (disk full or closed?)");
}

SystemState SystemState::read(std::istream& in) {
  char found[sizeof magic] = {};
  in.read(found, sizeof found);
  if (!in || std::memcmp(found, magic, sizeof magic) != 0)
    throw Error(
        "read_state: not a partita DEM state (the stream does not start with the magic "
        "'PTDEMST1'); give a file written by System::write_state");
  BinaryReader r(in);
  const auto version = r.value<std::uint32_t>("the format version");
  if (version < oldest_version || version > format_version)
    throw Error("read_state: the state has format version " + std::to_string(version) +
                "; this build reads versions " + std::to_string(oldest_version) + " to " +
                std::to_string(format_version) + " only (write it again with a matching build)");
  const auto bom = r.value<std::uint32_t>("the byte-order mark");
  if (bom != byte_order_mark)
    throw Error(
        "read_state: the state was written on a machine of another byte order; it cannot be "
        "read here");
  SystemState s;
  r.value(s.time_, "the time");
  s.steps_ = static_cast<long>(r.value<std::int64_t>("the step count"));
  s.particles_ = static_cast<std::size_t>(r.value<std::uint64_t>("the particle count"));
  s.body_ = r.string("the state body");
  s.origin_ = 0;
  s.version_ = version;
  return s;
}

SystemState System::save_state() const {
  sync_particles();
  std::ostringstream out(std::ios::binary);
  BinaryWriter w(out);
  write_body(w);
  SystemState s;
  s.body_ = std::move(out).str();
  s.time_ = time_;
  s.steps_ = steps_;
  s.particles_ = store_.size();
  s.origin_ = identity_;
  return s;
}

void System::restore_state(const SystemState& s) {
  if (s.particles_ != store_.size() && s.origin_ != 0 && s.origin_ != identity_) {
    std::ostringstream msg;
    msg << "restore_state: the state has " << s.particles_ << " particles and comes from another "
        << "system; this one has " << store_.size()
        << " (an in-memory state can only be restored into the system it came from; to move a "
           "state between systems set up alike, use write_state/read_state)";
    throw Error(msg.str());
  }
  std::istringstream in(s.body_, std::ios::binary);
  BinaryReader r(in);
  read_body(r, s.version_);
  pairs_.clear_waiting();  // (received histories belong to the state that was replaced)
  verlet_.store_replaced();
  partition_.invalidate();
  prepared_ = false;  // time step and scratch for the restored particle set; lists come with it
}

void System::write_state(std::ostream& out) const {
  save_state().write(out);
}

void System::read_state(std::istream& in) {
  restore_state(SystemState::read(in));
}

void System::write_body(BinaryWriter& w) const {
  w.value(body_tag);
  // set-up that the state must fit
  w.value(static_cast<std::int32_t>(model_.material_count()));
  w.value(static_cast<std::int32_t>(walls_.wall_count()));
  w.value(static_cast<std::int64_t>(walls_.planes().size()));
  w.value(static_cast<std::int64_t>(meshes_.size()));
  for (const TriangleMesh& m : meshes_) {
    w.value(static_cast<std::int64_t>(m.vertex_count()));
    w.value(static_cast<std::int64_t>(m.triangle_count()));
  }
  w.value(static_cast<std::int32_t>(hooks_.size()));
  for (int k = 0; k < hooks_.size(); ++k) w.string(hooks_[k].name());
  // particles with every registered array (histories with planes and meshes included)
  store_.write(w);
  mesh_contacts_.write(w);  // (format version 2: its rows; version 1 had store arrays)
  walls_.write(w);
  for (const TriangleMesh& m : meshes_) m.write_state(w);
  // the lists, the pairs' histories between their rows and build references (format version 1:
  // where the neighbour list wrote them when it held them)
  neighbors_.write_rows(w);
  pairs_.write(w);
  neighbors_.write_build_references(w);
  walls_.write_forces(w);
  w.value(time_);
  w.value(static_cast<std::int64_t>(steps_));
  w.value(skin_);
  w.value(static_cast<char>(forces_valid_));
  w.value(static_cast<char>(lists_current_));
  w.value(static_cast<std::int32_t>(builds_since_sort_));
  w.value(static_cast<std::int64_t>(sorts_));
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].write_state(w);
  // the energies (format version 3)
  const Energies& e = energies_;
  for (const double v : {e.friction, e.damping, e.breakage, e.gravity, e.stiffening, e.kinetic_start,
                         e.elastic_start, set_change_before_, energy_dt_})
    w.value(v);
  w.value(static_cast<char>(e.started));
  w.value(static_cast<char>(set_change_pending_));
  w.array(e.wall_work);
  w.array(e.mesh_work);
  w.value(end_tag);
}

// The set-up is checked first (nothing is changed when the state does not fit); a body that is
// inconsistent further on (corrupt data) throws with the system partly overwritten.
void System::read_body(BinaryReader& r, std::uint32_t version) {
  r.expect(body_tag, "the body tag");
  r.expect(static_cast<std::int32_t>(model_.material_count()), "the number of materials");
  r.expect(static_cast<std::int32_t>(walls_.wall_count()), "the number of walls");
  r.expect(static_cast<std::int64_t>(walls_.planes().size()), "the number of planes");
  r.expect(static_cast<std::int64_t>(meshes_.size()), "the number of meshes");
  for (const TriangleMesh& m : meshes_) {
    r.expect(static_cast<std::int64_t>(m.vertex_count()), "a mesh's vertex count");
    r.expect(static_cast<std::int64_t>(m.triangle_count()), "a mesh's triangle count");
  }
  r.expect(static_cast<std::int32_t>(hooks_.size()), "the number of step hooks");
  for (int k = 0; k < hooks_.size(); ++k) {
    const std::string name = r.string("a step hook name");
    if (name != hooks_[k].name())
      throw Error("state does not fit this system: step hook " + std::to_string(k) + " is '" +
                  name + "' in the state, '" + hooks_[k].name() + "' here");
  }
  store_.read(r);
  mesh_contacts_.read(r, store_.size());
  walls_.read(r);
  for (TriangleMesh& m : meshes_) m.read_state(r);
  neighbors_.read_rows(r);
  pairs_.read(r, neighbors_.pair_count(), version >= 5);
  neighbors_.read_build_references(r);
  walls_.read_forces(r);
  r.value(time_, "the time");
  steps_ = static_cast<long>(r.value<std::int64_t>("the step count"));
  r.value(skin_, "the skin");
  forces_valid_ = r.value<char>("the force flag") != 0;
  lists_current_ = r.value<char>("the list flag") != 0;
  builds_since_sort_ = r.value<std::int32_t>("the builds since the last sort");
  sorts_ = static_cast<long>(r.value<std::int64_t>("the sort count"));
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].read_state(r);
  Energies& e = energies_;
  for (double* v : {&e.friction, &e.damping, &e.breakage, &e.gravity, &e.stiffening,
                    &e.kinetic_start,
                    &e.elastic_start, &set_change_before_, &energy_dt_})
    r.value(*v, "the energies");
  e.started = r.value<char>("the energy flag") != 0;
  set_change_pending_ = r.value<char>("the set change flag") != 0;
  r.array(e.wall_work, "the wall work");
  r.array(e.mesh_work, "the mesh work");
  r.expect(end_tag, "the end tag");
  for (int k = 0; k < hooks_.size(); ++k) hooks_[k].restored(*this);
}

}  // namespace partita::dem
