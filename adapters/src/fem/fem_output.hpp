#pragma once
// The VTK file of an FE solver (solvers/fem), written by the interface's VTK XML writer.

#include <filesystem>
#include <span>

#include "partita/fem/indenter_contact.hpp"
#include "partita/fem/structural_solver.hpp"
#include "partita/interface/vtk_xml.hpp"

namespace partita::adapters {

/// The mesh as an UnstructuredGrid (.vtu; VTK_HEXAHEDRON, VTK_QUADRATIC_HEXAHEDRON, VTK_TETRA,
/// VTK_QUADRATIC_TETRA cells) with point arrays displacement [m], velocity [m/s], stress [Pa]
/// (nodal average; VTK's symmetric tensor order XX YY ZZ XY YZ XZ, the same as partita's Voigt
/// order), von_mises [Pa], and cell arrays region (Int32) and, on the nonlinear path,
/// equivalent_plastic_strain (element mean); with rigid indenters, the point array
/// contact_force [N] (the force of all of them on each node, at the committed state).
void write_fem_vtu(const fem::StructuralSolver& solver, const std::filesystem::path& path,
                   const vtk::Options& options,
                   std::span<const fem::IndenterContact* const> contacts = {});

/// VTK's cell type of an element type.
std::uint8_t vtk_cell_type(fem::ElementType type);

}  // namespace partita::adapters
