#pragma once
// Parameters of the crushing model (Breakage): seed 001, eq. 2, with the Weibull size effect.

#include "partita/dem/fragment_pattern.hpp"

#include <cstdint>

namespace partita::dem {

struct BreakageParameters {
  double limit_strength = 0.0;   ///< sigma_lim,0 [Pa] > 0: strength of a particle of size d0
  double reference_size = 0.0;   ///< d0 [m] > 0
  double weibull_modulus = 0.0;  ///< m [-] > 0: size effect (d/d0)^(-3/m) and scatter shape
  /// Per-particle scatter: each particle's strength is drawn from a Weibull law of modulus m
  /// whose characteristic value (37 % survive it) is sigma_lim,0 (d/d0)^(-3/m); false: every
  /// particle has exactly that value.
  bool scatter = true;
  double comminution_limit = 0.0;  ///< d_min [m] > 0: particles with d < d_min do not fragment
  /// What a particle with d < d_min does when a contact reaches its strength (eq. 2 with the
  /// size effect, as above it): false: nothing (it never breaks); true: it is crushed to powder,
  /// i.e. removed from the system, its mass and its kinetic and contact energy counted
  /// (BreakageCounters::powder_*). Powder carries no load: use it where the fines are few or
  /// where an unbreakable sphere would be squeezed through a gap narrower than itself.
  bool powder = false;
  /// (Exclusive with powder.) true: a particle with d < d_min yields in its contacts with the
  /// structure (meshes) and with other particles: the contact's mean pressure F/(pi a^2) is held
  /// at the particle's strength sigma (the same value that would break it above d_min; between
  /// two such particles the weaker one's), the overlap beyond becomes permanent (an
  /// elastic-perfectly plastic contact, Thornton 1997 with the yield pressure p_y = sigma;
  /// yield_overlap()) and its work is dissipated (booked with the damping). A fragment that two
  /// closing faces or its neighbours pinch is flattened instead of storing the Hertz energy of an
  /// overlap of its own size; its mass stays in the bed. A mesh contact yields until its
  /// permanent overlap is the particle's radius (the centre at the face) and is elastic beyond;
  /// a particle whose contact pressure reaches 1.5 times its strength there (or against a plane,
  /// which stays elastic, or in a hard impact) is crushed to powder as with `powder`, and so is one
  /// pinched between two faces closer than its radius (MeshContacts), so that a fragment pressed
  /// into the structure or caught in a closing gap is dust there, not pushed through a face.
  bool yield = false;
  FragmentPattern::Kind pattern = FragmentPattern::Kind::apollonian_14;
  /// false: the mass the inscribed fragments cannot hold is lost (counted); true: it is restored
  /// (fragments carry the parent's mass and moment of inertia about its centre; counted).
  bool restore_mass = false;
  std::uint64_t seed = 1;  ///< strengths and fragment orientations are drawn from (seed, id)
};

}  // namespace partita::dem
