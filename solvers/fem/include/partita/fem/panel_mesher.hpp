#pragma once
#include <vector>

#include "partita/fem/element_type.hpp"
#include "partita/fem/mesh.hpp"

namespace partita::fem {

// Structured mesh of a cellular panel: a double-hull side section over the footprint
// [origin.x, origin.x + footprint_x] x [origin.y, origin.y + footprint_y]. Through the depth (z):
// the outer plate [z0, z0 + outer_thickness] (its face z = z0 is the struck side), the cavity of
// clear height `depth`, the inner plate of inner_thickness above it. Webs of web_thickness
// join the plates across the cavity: transverse frames (mid-planes at x = origin.x + frames[k],
// over the whole y span) and longitudinal stringers / girders (mid-planes at y = origin.y +
// stringers[k], over the whole x span); where they cross they share the cells.
//
// The grid is a tensor product whose lines include every plate and web face: across each web
// web_cells cells, through each plate outer_cells / inner_cells, over the depth depth_cells (0:
// ceil(depth / element_size)), and each gap between webs (or a web and the footprint's edge)
// in ceil(gap / element_size) equal cells. Its solid cells are the plates everywhere and the
// webs in the cavity's layers; one element per cell (Hex8, Hex20) or six (Tet4, Tet10), sharing
// nodes where cells touch (conforming joints), as make_box_mesh() makes them.
//
// Result: regions "outer_plate", "inner_plate" and (with webs) "webs". Faces (outward surface
// elements) and node sets of the same names: "outer" (the outer plate's struck face z = z0,
// normal -z), "inner" (the inner plate's face toward the ship's interior, normal +z), "xmin",
// "xmax", "ymin", "ymax" (the section's edge planes: plate and web ends, for supports), and
// "cell_<i>_<j>" for each cavity cell: every face bounding it (the plates' faces toward the
// cavity and the webs' sides), normals pointing into the cavity (as the hollow box's "inner").
// Cells are numbered along x (i, from origin.x) and y (j) by the gaps between the webs; a gap
// between a web and the footprint's edge is a cell open on that side (no face there). The same
// cavity faces grouped by part, whatever the number of cells: "cavity" (every cell's faces),
// "cavity_outer" (the outer plate's faces toward the cavity, normal +z), "cavity_inner" (the
// inner plate's, normal -z) and "cavity_webs" (the webs' sides); a face is in its cell's set, in
// "cavity" and in one part's set. Node set "all" as well.
struct PanelSpec {
  Vec3 origin = Vec3::Zero();     // min x, min y, and z of the outer plate's struck face [m]
  double footprint_x = 1.0;       // extent along x [m]
  double footprint_y = 1.0;       // extent along y [m]
  double outer_thickness = 0.01;  // [m]
  double inner_thickness = 0.01;  // [m]
  double depth = 0.1;             // clear distance between the plates [m]
  double web_thickness = 0.01;    // [m]
  std::vector<double> frames;     // x of the frames' mid-planes, measured from origin.x [m]
  std::vector<double> stringers;  // y of the stringers' mid-planes, measured from origin.y [m]
  double element_size = 0.05;     // target in-plane element edge (and over the depth) [m]
  int outer_cells = 1;            // cells through the outer plate
  int inner_cells = 1;            // cells through the inner plate
  int web_cells = 1;              // cells through a web's thickness
  int depth_cells = 0;            // cells over the depth (0: from element_size)
  ElementType element = ElementType::Hex8;
};

// The cells form of a panel: cells_x x cells_y cavity cells closed on every side, the webs'
// mid-planes at web_spacing (centre to centre) from a web flush with the footprint's low edge
// (at web_thickness / 2) to one flush with its high edge. Sets spec.frames, spec.stringers and
// the footprint (cells * web_spacing + web_thickness along each axis); spec.web_thickness must be
// set first. Each cell's clear width is web_spacing - web_thickness. Throws Error if a count is
// < 1, web_thickness is not positive or web_spacing is not at least 2 web_thickness (the cells
// would be thinner than a web).
void place_webs_by_cells(PanelSpec& spec, int cells_x, int cells_y, double web_spacing);

// Throws Error (stating the rule, the value and what is allowed) if a size or thickness is not
// positive, a count is < 1 (depth_cells < 0), a web reaches beyond the footprint, two webs
// overlap or touch, or a web leaves a gap thinner than a web to its neighbour or to the edge (a
// sliver of thin elements: place such a web flush with the edge, at web_thickness / 2).
Mesh make_panel_mesh(const PanelSpec& spec);

}  // namespace partita::fem
