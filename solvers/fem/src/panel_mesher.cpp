#include "partita/fem/panel_mesher.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "masked_grid.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// One axis of the grid: the cell boundaries, and for each cell the web it lies in (-1: none)
// and the gap between webs it lies in (-1: in a web).
struct Axis {
  std::vector<double> lines;
  std::vector<int> web;
  std::vector<int> gap;
};

// In-plane axis d (0: x, 1: y) of length `length` from `origin`, with webs of thickness t
// centred at `positions` (from the origin). `what` names the webs in messages.
Axis web_axis(double origin, double length, const std::vector<double>& positions, double t,
              const PanelSpec& spec, const char* what, const char* axis) {
  std::vector<double> p = positions;
  std::sort(p.begin(), p.end());
  const double tol = 1e-9 * length;
  for (double x : p) {
    if (!std::isfinite(x) || x - 0.5 * t < -tol || x + 0.5 * t > length + tol)
      throw Error(std::string("panel mesh: the ") + what + " at " + axis + " = " + num(x) +
                  " m reaches beyond the footprint [0, " + num(length) +
                  "] m: with web_thickness " + num(t) + " m its position must lie in [" +
                  num(0.5 * t) + ", " + num(length - 0.5 * t) + "] m");
  }
  for (std::size_t k = 1; k < p.size(); ++k) {
    const double gap = (p[k] - 0.5 * t) - (p[k - 1] + 0.5 * t);
    if (gap <= tol)
      throw Error(std::string("panel mesh: the ") + what + " at " + axis + " = " + num(p[k - 1]) +
                  " and " + num(p[k]) + " m overlap (web_thickness " + num(t) +
                  " m): webs must be at least 2 web thicknesses apart, centre to centre");
  }
  // spans: [start, end, web index or -1]
  struct Span {
    double a, b;
    int web;
  };
  std::vector<Span> spans;
  double at = 0.0;
  const auto add_gap = [&](double b, const char* between) {
    const double gap = b - at;
    if (gap <= tol) return;  // flush: no gap
    if (gap < t - tol)
      throw Error(std::string("panel mesh: a gap of ") + num(gap) + " m along " + axis + " " +
                  between + " is thinner than a web (" + num(t) +
                  " m): its elements would be slivers; move the web flush (position " +
                  num(0.5 * t) + " or " + num(length - 0.5 * t) + " m at an edge) or at least " +
                  num(t) + " m away");
    spans.push_back({at, b, -1});
  };
  for (std::size_t k = 0; k < p.size(); ++k) {
    const std::string between = std::string("before the ") + what + " at " + num(p[k]) + " m";
    double a = p[k] - 0.5 * t, b = p[k] + 0.5 * t;
    if (a - at <= tol) a = at;  // flush with the edge (rounding)
    if (length - b <= tol) b = length;
    add_gap(a, between.c_str());
    spans.push_back({a, b, static_cast<int>(k)});
    at = b;
  }
  add_gap(length, (std::string("after the last ") + what + ", to the footprint's edge").c_str());
  Axis axis_out;
  axis_out.lines.push_back(origin);
  int gaps = 0;
  for (const Span& s : spans) {
    const long n =
        s.web >= 0
            ? spec.web_cells
            : std::max(1L, static_cast<long>(std::ceil((s.b - s.a) / spec.element_size - 1e-9)));
    for (long c = 1; c <= n; ++c) {
      // the last line of a span is its end exactly (the next span starts there)
      axis_out.lines.push_back(
          c == n ? origin + s.b
                 : origin + s.a + (s.b - s.a) * static_cast<double>(c) / static_cast<double>(n));
      axis_out.web.push_back(s.web);
      axis_out.gap.push_back(s.web >= 0 ? -1 : gaps);
    }
    if (s.web < 0) ++gaps;
  }
  return axis_out;
}

void check(const PanelSpec& s) {
  const auto positive = [](double v, const char* key) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw Error(std::string("panel mesh: ") + key + " must be > 0 m, got " + num(v));
  };
  positive(s.footprint_x, "footprint_x");
  positive(s.footprint_y, "footprint_y");
  positive(s.outer_thickness, "outer_thickness");
  positive(s.inner_thickness, "inner_thickness");
  positive(s.depth, "depth");
  positive(s.element_size, "element_size");
  if (!s.frames.empty() || !s.stringers.empty()) positive(s.web_thickness, "web_thickness");
  const auto at_least_one = [](int v, const char* key) {
    if (v < 1)
      throw Error(std::string("panel mesh: ") + key + " must be >= 1, got " + std::to_string(v));
  };
  at_least_one(s.outer_cells, "outer_cells");
  at_least_one(s.inner_cells, "inner_cells");
  at_least_one(s.web_cells, "web_cells");
  if (s.depth_cells < 0)
    throw Error("panel mesh: depth_cells must be >= 1 (or 0: from element_size), got " +
                std::to_string(s.depth_cells));
}

}  // namespace

void place_webs_by_cells(PanelSpec& spec, int cells_x, int cells_y, double web_spacing) {
  const double t = spec.web_thickness;
  if (!(t > 0.0) || !std::isfinite(t))
    throw Error("panel mesh: web_thickness must be > 0 m, got " + num(t));
  for (const auto& [n, axis] : {std::pair{cells_x, "x"}, std::pair{cells_y, "y"}})
    if (n < 1)
      throw Error(std::string("panel mesh: the number of cells along ") + axis +
                  " must be >= 1, got " + std::to_string(n));
  if (!std::isfinite(web_spacing) || !(web_spacing >= 2.0 * t))
    throw Error("panel mesh: web_spacing (centre to centre) must be at least 2 web_thickness (" +
                num(2.0 * t) + " m: a cell at least as wide as a web), got " + num(web_spacing) +
                " m");
  // webs flush with both edges: the first at t / 2, the last at t / 2 + n * spacing
  const auto place = [&](int n, std::vector<double>& webs, double& footprint) {
    webs.clear();
    for (int k = 0; k <= n; ++k) webs.push_back(0.5 * t + static_cast<double>(k) * web_spacing);
    footprint = static_cast<double>(n) * web_spacing + t;
  };
  place(cells_x, spec.frames, spec.footprint_x);
  place(cells_y, spec.stringers, spec.footprint_y);
}

Mesh make_panel_mesh(const PanelSpec& spec) {
  check(spec);
  const Axis x = web_axis(spec.origin.x(), spec.footprint_x, spec.frames, spec.web_thickness, spec,
                          "frame", "x");
  const Axis y = web_axis(spec.origin.y(), spec.footprint_y, spec.stringers, spec.web_thickness,
                          spec, "stringer", "y");
  // z: outer plate, cavity, inner plate
  const long n_depth =
      spec.depth_cells > 0
          ? spec.depth_cells
          : std::max(1L, static_cast<long>(std::ceil(spec.depth / spec.element_size - 1e-9)));
  const double z0 = spec.origin.z(), z1 = z0 + spec.outer_thickness, z2 = z1 + spec.depth,
               z3 = z2 + spec.inner_thickness;
  std::vector<double> zl;
  const auto span = [&](double a, double b, long n) {
    for (long c = zl.empty() ? 0 : 1; c <= n; ++c)
      zl.push_back(c == n ? b : a + (b - a) * static_cast<double>(c) / static_cast<double>(n));
  };
  span(z0, z1, spec.outer_cells);
  span(z1, z2, n_depth);
  span(z2, z3, spec.inner_cells);
  const long outer_top = spec.outer_cells;        // first cavity layer
  const long inner_bottom = outer_top + n_depth;  // first inner-plate layer

  detail::MaskedGrid grid;
  grid.lines = {x.lines, y.lines, zl};
  grid.regions = {"outer_plate", "inner_plate"};
  const bool webs = !spec.frames.empty() || !spec.stringers.empty();
  if (webs) grid.regions.push_back("webs");
  const auto in_web = [&](const detail::GridCell& c) {
    return x.web[static_cast<std::size_t>(c[0])] >= 0 || y.web[static_cast<std::size_t>(c[1])] >= 0;
  };
  grid.region = [&](const detail::GridCell& c) {
    if (c[2] < outer_top) return 0;
    if (c[2] >= inner_bottom) return 1;
    return in_web(c) ? 2 : -1;
  };
  static const std::array<std::string, 4> edges = {"xmin", "xmax", "ymin", "ymax"};
  static const std::string cavity = "cavity", cavity_outer = "cavity_outer",
                           cavity_inner = "cavity_inner", cavity_webs = "cavity_webs";
  grid.faces = [&](const detail::GridCell& c, int d, int upper, bool outside,
                   std::vector<std::string>& out) {
    if (outside) {
      out.push_back(d == 2 ? (upper ? "inner" : "outer")
                           : edges[static_cast<std::size_t>(2 * d + upper)]);
      return;
    }
    detail::GridCell across = c;
    across[d] += upper ? 1 : -1;
    out.push_back("cell_" + std::to_string(x.gap[static_cast<std::size_t>(across[0])]) + "_" +
                  std::to_string(y.gap[static_cast<std::size_t>(across[1])]));
    // by part: a face toward the cavity along z is a plate's (the outer plate's on its upper
    // side), in the plane a web's side
    out.push_back(cavity);
    out.push_back(d != 2 ? cavity_webs : upper ? cavity_outer : cavity_inner);
  };
  return detail::make_masked_grid_mesh(grid, spec.element);
}

}  // namespace partita::fem
