#pragma once
#include <string>

#include "partita/fem/structural_solver.hpp"

namespace partita::fem {

// Writes the solver's mesh and point data (displacement, velocity, stress as a 6-component
// symmetric tensor XX YY ZZ XY YZ XZ, von_mises) as a VTK XML UnstructuredGrid (.vtu, ASCII)
// to path. Writes path + ".tmp" first and renames it, so a reader never sees a partial file.
// Throws Error when the file cannot be written.
void write_vtu(const std::string& path, const StructuralSolver& solver);

}  // namespace partita::fem
