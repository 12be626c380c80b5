#pragma once
// What the crushing model (Breakage) has done since it was added (monitors). Saved and restored
// with the System state.

#include <cstdint>

namespace partita::dem {

struct BreakageCounters {
  std::int64_t events = 0;         ///< particles broken
  std::int64_t fragments = 0;      ///< fragments created
  double fragment_mass = 0.0;      ///< mass of the fragments created [kg]
  double mass_lost = 0.0;          ///< parent mass the fragments do not hold, lost [kg]
  double mass_restored = 0.0;      ///< the same, given back to the fragments [kg]
  double energy_released = 0.0;    ///< elastic energy of the parents' contacts minus that of the
                                   ///< fragments' contacts right after, plus the kinetic energy
                                   ///< carried away by lost mass, plus powder_energy [J]
  double smallest_fragment = 0.0;  ///< smallest fragment diameter so far [m] (0: none yet)
  std::int64_t powder_events = 0;  ///< particles below d_min crushed to powder (removed)
  double powder_mass = 0.0;        ///< their mass, gone from the system [kg]
  double powder_energy = 0.0;      ///< their kinetic energy and the elastic (normal Hertz) energy
                                   ///< of their contacts when removed [J]
};

}  // namespace partita::dem
