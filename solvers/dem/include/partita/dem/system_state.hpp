#pragma once
// A complete copy of a System's dynamic state (System::save_state()): particles with their ids and
// every registered per-particle array, contact histories, neighbour lists, planes, mesh vertices,
// forces, time, step count and the step hooks' state. Restoring it (System::restore_state()) and
// stepping on gives results bit-identical to never having left (implicit coupling repeats
// windows from such states).
//
// The state is held in its serialised form, so the same bytes are what write() puts in a restart
// file and read() takes back:
//   header   8 bytes magic "PTDEMST1", uint32 format version, uint32 byte-order mark 0x01020304,
//            float64 time [s], int64 step count, uint64 particle count, uint64 body size
//   body     set-up check (material, plane, mesh and hook counts and names), the particle store
//            (per array: name, width, element size, contents), the mesh contact rows (particle,
//            slots, contacts, feature keys, histories, records), plane positions and velocities,
//            per mesh its vertex positions/velocities/forces, neighbour lists with histories,
//            wall forces, System counters, each hook's state
// Values are raw little-endian IEEE 754 bytes of this build; a file from a machine of another
// byte order is refused. read() throws partita::dem::Error on a bad magic, another version or
// byte order, and a truncated stream; restoring throws Error when the body does not fit the
// system (another set-up) or is inconsistent.
//
//   std::ofstream out("restart.dem", std::ios::binary);  system.write_state(out);
//   std::ifstream in("restart.dem", std::ios::binary);   other.read_state(in);  // same set-up

#include <cstdint>
#include <iosfwd>
#include <string>

namespace partita::dem {

class SystemState {
 public:
  // 2: mesh contact histories as rows of the particles near a mesh (MeshContacts), after the
  // particle store, which no longer has the four mesh arrays of version 1
  // 3: the cumulative energies (System::energies()) after the hooks' state
  // 4: the breakage counters' powder fields
  // 5: the pairs' permanent overlaps (PairContacts) after their histories; version 4 is read
  // as a state without them
  static constexpr std::uint32_t format_version = 5;
  static constexpr std::uint32_t oldest_version = 4;

  double time() const { return time_; }
  long step_count() const { return steps_; }
  std::size_t particle_count() const { return particles_; }
  /// Size of the serialised state [bytes].
  std::size_t size() const { return body_.size(); }

  /// Writes the header and body (binary; open the stream with std::ios::binary).
  void write(std::ostream& out) const;
  /// Reads what write() wrote. Throws Error on a bad magic, another version or byte order, or a
  /// stream that ends early.
  static SystemState read(std::istream& in);

 private:
  friend class System;
  std::string body_;
  double time_ = 0.0;
  long steps_ = 0;
  std::size_t particles_ = 0;
  std::uint64_t origin_ = 0;  // System::identity_ of the saving system; 0: read from a stream
  std::uint32_t version_ = format_version;  // the format of body_
};

}  // namespace partita::dem
