#include "fem_panel_config.hpp"

#include <fmt/format.h>
#include <cmath>
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/panel_mesher.hpp"

namespace partita::adapters {

using config::Node;
using config::Spec;

std::shared_ptr<Spec> fem_panel_spec() {
  auto p = std::make_shared<Spec>(
      "panel",
      "a cellular panel (a double-hull side section): an outer and an inner plate joined by webs "
      "(frames across x, stringers across y) into cavity cells. Regions outer_plate, "
      "inner_plate, webs; faces and node sets outer (the outer plate's struck face z = "
      "origin.z, normal -z), inner (the inner plate's face toward the interior, normal +z), "
      "xmin, xmax, ymin, ymax (the section's edges), cell_<i>_<j> (every face bounding "
      "cavity cell i along x, j along y, normals into the cavity: a DEM contact surface), the "
      "same faces by part whatever the cell count: cavity (all of them), cavity_outer, "
      "cavity_inner (the plates' faces toward the cavity) and cavity_webs (the webs' sides), "
      "and all. The webs are given either as cells (with web_spacing: every cell closed, the "
      "footprint follows) or as footprint with frames and stringers; there a web flush with an "
      "edge (position web_thickness / 2 from it) closes the cells there, otherwise the edge "
      "cells are open on that side");
  p->reals("origin", "min x, min y, and z of the outer plate's struck face").unit("m").size(3);
  p->reals("centre",
           "instead of origin: x and y of the footprint's centre, and z of the outer plate's "
           "struck face (the section grows about it when cells or web_spacing change)")
      .unit("m")
      .size(3);
  p->reals("footprint", "extents along x and y (not with cells: it follows from them)")
      .unit("m")
      .size(2)
      .min(0.0, true);
  p->integers("cells",
              "cavity cells along x and y, closed on every side: webs at web_spacing from one "
              "flush with the low edge to one flush with the high edge (footprint: cells x "
              "web_spacing + web_thickness); instead of footprint, frames and stringers")
      .size(2)
      .min(1)
      .max(100000);
  p->real("web_spacing",
          "with cells: distance between the webs' mid-planes (a cell's clear width is "
          "web_spacing - web_thickness)")
      .unit("m")
      .positive();
  p->real("outer_thickness", "outer plate thickness t_o").unit("m").positive().required();
  p->real("inner_thickness", "inner plate thickness t_i").unit("m").positive().required();
  p->real("depth", "clear distance h between the plates (the cells' height)")
      .unit("m")
      .positive()
      .required();
  p->real("web_thickness", "thickness t_w of every web (needed with frames or stringers)")
      .unit("m")
      .positive();
  p->reals("frames",
           "x of the transverse webs' mid-planes, measured from origin.x (each web within the "
           "footprint; webs at least 2 t_w apart; a gap to a neighbour or an edge at least t_w "
           "or none)")
      .unit("m");
  p->reals("stringers",
           "y of the longitudinal webs' (stringers', girders') mid-planes, measured from "
           "origin.y (same rules)")
      .unit("m");
  p->real("element_size",
          "target element edge in the plane and over the depth: each gap between webs in "
          "ceil(gap / element_size) equal cells")
      .unit("m")
      .positive()
      .required();
  p->integer("outer_cells", "cells through the outer plate").min(1).def(1);
  p->integer("inner_cells", "cells through the inner plate").min(1).def(1);
  p->integer("web_cells", "cells through a web's thickness").min(1).def(1);
  p->integer("depth_cells", "cells over the depth (default: ceil(depth / element_size))").min(1);
  p->one_of({"origin", "centre"});
  p->one_of({"footprint", "cells"});
  p->one_of({"frames", "cells"}, false);
  p->one_of({"stringers", "cells"}, false);
  return p;
}

fem::Mesh build_panel_mesh(const Node& n, fem::ElementType element, double max_cells) {
  fem::PanelSpec s;
  s.outer_thickness = n.real("outer_thickness");
  s.inner_thickness = n.real("inner_thickness");
  s.depth = n.real("depth");
  if (n.has("cells")) {
    // the cells form: the webs and the footprint follow from the count and the spacing
    if (!n.has("web_spacing"))
      n["cells"].fail(
          "a panel given by cells needs web_spacing (the distance between the webs' "
          "mid-planes, m)");
    if (!n.has("web_thickness"))
      n["cells"].fail("a panel given by cells needs web_thickness (the webs' thickness, m)");
    s.web_thickness = n.real("web_thickness");
    const auto cells = n.integers("cells");
    try {
      fem::place_webs_by_cells(s, static_cast<int>(cells[0]), static_cast<int>(cells[1]),
                               n.real("web_spacing"));
    } catch (const fem::Error& e) {
      n["web_spacing"].fail(e.what());
    }
  } else {
    if (n.has("web_spacing"))
      n["web_spacing"].fail(
          "web_spacing places the webs of a panel given by cells: with footprint, give the "
          "webs' positions as frames and stringers instead (or replace footprint, frames and "
          "stringers by cells)");
    const auto footprint = n.reals("footprint");
    s.footprint_x = footprint[0];
    s.footprint_y = footprint[1];
    if (n.has("frames")) s.frames = n.reals("frames");
    if (n.has("stringers")) s.stringers = n.reals("stringers");
    if (!s.frames.empty() || !s.stringers.empty()) {
      if (!n.has("web_thickness"))
        n.fail("a panel with frames or stringers needs web_thickness (the webs' thickness, m)");
      s.web_thickness = n.real("web_thickness");
    }
  }
  if (n.has("origin")) {
    s.origin = n.vec3("origin");
  } else {  // the footprint about its centre
    const fem::Vec3 c = n.vec3("centre");
    s.origin = fem::Vec3(c.x() - 0.5 * s.footprint_x, c.y() - 0.5 * s.footprint_y, c.z());
  }
  s.element_size = n.real("element_size");
  s.outer_cells = static_cast<int>(n.integer("outer_cells"));
  s.inner_cells = static_cast<int>(n.integer("inner_cells"));
  s.web_cells = static_cast<int>(n.integer("web_cells"));
  if (n.has("depth_cells")) s.depth_cells = static_cast<int>(n.integer("depth_cells"));
  s.element = element;
  // An upper bound of the grid's cells, as reals (a typing error must not wrap a count).
  const auto along = [&](double length, double webs) {
    return std::ceil(length / s.element_size) + webs * (static_cast<double>(s.web_cells) + 1.0);
  };
  const double depth = s.depth_cells > 0 ? s.depth_cells : std::ceil(s.depth / s.element_size);
  const double cells = along(s.footprint_x, static_cast<double>(s.frames.size())) *
                       along(s.footprint_y, static_cast<double>(s.stringers.size())) *
                       (depth + s.outer_cells + s.inner_cells);
  if (cells > max_cells)
    n["element_size"].fail(fmt::format(
        "an element size of {:.4g} m makes about {:.3g} cells, more than {:.0e}, far beyond "
        "what one machine can solve; check the size and the units",
        s.element_size, cells, max_cells));
  try {
    return fem::make_panel_mesh(s);
  } catch (const fem::Error& e) {
    // the mesher names what is wrong: fail at that key
    const std::string what = e.what();
    if (n.has("cells")) n["cells"].fail(what);
    if (what.find("frame") != std::string::npos && n.has("frames")) n["frames"].fail(what);
    if (what.find("stringer") != std::string::npos && n.has("stringers")) n["stringers"].fail(what);
    n.fail(what);
  }
}

}  // namespace partita::adapters
