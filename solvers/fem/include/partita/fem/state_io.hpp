#pragma once
#include <istream>
#include <ostream>

#include "partita/fem/solver_state.hpp"

namespace partita::fem {

// Versioned binary form of a SolverState (restart files). Layout, all little-endian as written
// by this machine (a restart is read back on the machine that wrote it):
//   magic "PFEMSTAT" (8 bytes), format version (uint32), then every field of SolverState in
//   declaration order: scalars as 8 bytes, vectors as a uint64 length and the raw doubles,
//   matrices as rows, cols and the raw doubles, maps as a count and (name, matrix) pairs.
// Doubles are copied bit for bit, so write -> read -> restore_state -> continue is
// bit-identical to never stopping.
inline constexpr unsigned kStateFormatVersion = 1;

// Throws Error when the stream fails.
void write_state(std::ostream& out, const SolverState& state);
// Throws Error on a wrong magic, an unknown version or a truncated / failing stream.
SolverState read_state(std::istream& in);

}  // namespace partita::fem
