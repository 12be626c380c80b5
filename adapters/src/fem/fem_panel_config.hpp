#pragma once
// The FEM adapter's key mesh.panel: a cellular panel (double-hull side section) from
// fem::make_panel_mesh(), beside mesh.box and mesh.gmsh.
//   mesh.panel  {origin, footprint, outer_thickness, inner_thickness, depth, web_thickness,
//                frames, stringers, element_size, outer_cells, inner_cells, web_cells,
//                depth_cells}
// Regions outer_plate, inner_plate, webs (energies by part); faces and node sets outer, inner,
// xmin, xmax, ymin, ymax and cell_<i>_<j> (see partita/fem/panel_mesher.hpp).

#include <memory>

#include "partita/fem/element_type.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/interface/config.hpp"

namespace partita::adapters {

std::shared_ptr<config::Spec> fem_panel_spec();
// The mesh of mesh.panel; a bad value fails at its key (the rule, the value, what is allowed).
// A grid of more than max_cells cells is refused at element_size.
fem::Mesh build_panel_mesh(const config::Node& panel, fem::ElementType element, double max_cells);

}  // namespace partita::adapters
