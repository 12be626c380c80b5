#pragma once
// A model that acts on a System at fixed points of every step, beside the integrator (as LAMMPS
// fixes do): breakage now; insertion and deletion regions later. Each hook lives in its own file.
//
// Call order within System::step(dt), for the hooks in the order they were added:
//   1. velocity Verlet first half, forces at t + dt and the second half kick (one fused pass);
//   2. post_force(system, dt): forces, torques and velocities at t + dt are complete; if the hook
//      asked for it (wants_contact_load()), System::contact_load() holds each particle's largest
//      contact load of this pass;
//   3. time and step count advance;
//   4. end_of_step(system, dt): the place to change the particle set (System::remove_particles,
//      System::add_particle): the next step recomputes forces and neighbour lists first.
// attach(system) is called once by System::add_hook: register per-particle arrays there
// (System::store().add_array), so that they are added, removed, permuted, saved and restored
// with the particles. Whatever else a hook changes between steps (counters, random-number
// state) is written by write_state() and read back by read_state(): System::save_state() and
// restore_state() include it, so a repeated window or a restart continues bit-identically.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"

#include "partita/dem/exact_sum.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace partita::dem {

class System;

class StepHook {
 public:
  virtual ~StepHook() = default;
  /// Name, written with the state (a state only goes back into a system with the same hooks).
  virtual std::string name() const = 0;
  /// A copy for a copied System (its per-particle arrays are copied with the store).
  virtual std::unique_ptr<StepHook> clone() const = 0;
  virtual void attach(System& /*system*/) {}
  /// True: the force pass records per particle the largest contact load
  /// F_n (E*/R*)^2 (System::contact_load()).
  virtual bool wants_contact_load() const { return false; }
  /// With wants_contact_load(): the handle of a per-particle store array (double, width 1) of
  /// load limits, or -1. The force pass compares each particle's load with its limit as the load
  /// is completed (in the threads' own loops: no extra pass, no barrier) and
  /// System::contact_load_reached() says whether any particle reached its limit, so a hook that
  /// acts on a few particles need not look at every particle at every step. New particles take
  /// the array's default; one below 0 makes them count as reached (the hook then sets their
  /// limits). One hook per system may have limits.
  virtual int contact_load_limit() const { return -1; }
  /// Particles that yield in their contacts: the handle of a per-particle store array (double,
  /// width 1) of yield pressures [Pa] (values <= 0: none yet) and the diameter below which they
  /// apply ({-1, 0}: none). A mesh or pair contact of such a particle holds its mean Hertz
  /// pressure F/(pi a^2) at the yield pressure (a pair of two: the smaller), the overlap beyond
  /// it becoming permanent (MeshContactRecord::pre_overlap; PairContacts' per-slot permanent
  /// overlap). One hook per system may have them.
  struct ContactYield {
    int pressure = -1;
    double below_diameter = 0.0;
  };
  virtual ContactYield contact_yield() const { return {}; }
  virtual void post_force(System& /*system*/, double /*dt*/) {}
  virtual void end_of_step(System& /*system*/, double /*dt*/) {}
  virtual void write_state(BinaryWriter& /*out*/) const {}
  virtual void read_state(BinaryReader& /*in*/) {}
  /// After a state was read or restored (System::read_state(), restore_state()): the particles
  /// and their arrays are the state's; a hook derives again what follows from them.
  virtual void restored(System& /*system*/) {}

  // ---- a hook that replaces particles, on a bed split into subdomains ------------------------
  // On a split bed (SubdomainStepper, subdomain.hpp) the subdomains must agree on every change of
  // the particle set: System::phase_finish() does not call end_of_step() of a hook whose
  // replaces_particles() is true. The stepper instead calls, after each step, choose() on every
  // subdomain for the particles it owns, gives the new particles ids that do not depend on the
  // split (from the replaced particles' ids in ascending order), calls replace(), builds the
  // split's ghosts and lists again, takes a force pass, and calls settled(). Counters that the
  // monitors add over the subdomains are exact sums (sums()), so that their totals do not depend
  // on the split either (SubdomainStepper::hook_sums()).
  virtual bool replaces_particles() const { return false; }
  /// How many new particles each replaced particle gets.
  virtual int successors() const { return 0; }
  /// Appends, ascending, the particles with skip[i] == 0 that it replaces after this step by
  /// successors() new ones (`replaced`) or removes without successor (`removed`).
  virtual void choose(System& /*system*/, const std::vector<char>& /*skip*/,
                      std::vector<std::size_t>& /*replaced*/,
                      std::vector<std::size_t>& /*removed*/) {}
  /// Replaces and removes the particles choose() gave; the new particles of replaced[k] take the
  /// ids first_id[k], first_id[k] + 1, ...
  virtual void replace(System& /*system*/, const std::vector<std::size_t>& /*replaced*/,
                       const std::vector<std::size_t>& /*removed*/,
                       const std::vector<std::int64_t>& /*first_id*/) {}
  /// After replace() on every subdomain, once the lists hold the new set (ghosts included) and a
  /// force pass is done: what is left to count for the new particles this subdomain owns now
  /// (skip: the ghosts), those with ids in [first_id, end_id) (a new particle may have moved to
  /// another subdomain at the build).
  virtual void settled(System& /*system*/, const std::vector<char>& /*skip*/,
                       std::int64_t /*first_id*/, std::int64_t /*end_id*/) {}
  /// The counters as exact sums, in a fixed order; set_sums() puts such sums back (a split bed's
  /// restart: the totals on one subdomain, none on the others).
  virtual std::vector<ExactSum> sums() const { return {}; }
  virtual void set_sums(const std::vector<ExactSum>& /*sums*/) {}
};

}  // namespace partita::dem
