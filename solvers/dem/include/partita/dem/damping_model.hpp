#pragma once
// How the coefficient of restitution e becomes a viscous damping coefficient of the Hertz contact.
//
// Both models damp with gamma = 2 zeta sqrt(S m*) (S = S_n or S_t, the current contact
// stiffnesses); they differ in the damping ratio zeta(e) and in whether a tensile normal force is
// allowed:
// - calibrated (default): zeta is found once per interaction such that the damped Hertz
//   oscillator realises exactly the requested e (RestitutionCalibration), and F_n >= 0 (no
//   attraction at the end of the contact, as recommended by Thornton, Cummins & Cleary, Powder
//   Technol. 233 (2013) 30-46).
// - liggghts: zeta = -sqrt(5/6) beta, beta = ln(e)/sqrt(ln(e)^2 + pi^2) (the linear-spring
//   expression used by LIGGGHTS/EDEM), F_n not clamped and the friction cap mu |F_n|; its realised
//   restitution differs from e (Antypov & Elliott, EPL 94 (2011) 50004). Used for the peer
//   benchmark.

namespace partita::dem {

enum class DampingModel { calibrated, liggghts };

}  // namespace partita::dem
