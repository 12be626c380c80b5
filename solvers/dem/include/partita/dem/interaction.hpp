#pragma once
// Parameters of the contact between two materials (particle-particle, particle-plane or
// particle-mesh: walls and meshes have a material id like particles).

namespace partita::dem {

struct Interaction {
  double friction = 0.0;          ///< Coulomb coefficient mu [-], >= 0 (0: no tangential force)
  double restitution = 1.0;       ///< normal coefficient of restitution e [-], in (0, 1]
  double rolling_friction = 0.0;  ///< mu_r [-], >= 0: constant rolling torque mu_r F_n R* (0: off)
};

}  // namespace partita::dem
