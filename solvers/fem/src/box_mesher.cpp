#include "partita/fem/box_mesher.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "masked_grid.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// Cell boundaries along axis d: a solid box has spec.cells[d] equal cells; a hollow box has
// wall_cells cells through each wall and spec.cells[d] across the cavity between them.
std::vector<double> axis_lines(const BoxSpec& spec, int d) {
  const double o = spec.origin[d], s = spec.size[d], t = spec.wall_thickness;
  const long n = spec.cells[d];
  std::vector<double> lines;
  if (t == 0.0) {
    for (long g = 0; g <= n; ++g)
      lines.push_back(o + s * static_cast<double>(g) / static_cast<double>(n));
    return lines;
  }
  // piecewise uniform: [o, o+t] in wall cells, [o+t, o+s-t] in n, [o+s-t, o+s] in wall cells
  const long w = spec.wall_cells;
  for (long g = 0; g <= w; ++g)
    lines.push_back(o + t * static_cast<double>(g) / static_cast<double>(w));
  for (long g = 1; g <= n; ++g)
    lines.push_back(o + t + (s - 2 * t) * static_cast<double>(g) / static_cast<double>(n));
  for (long g = w - 1; g >= 0; --g)
    lines.push_back(o + s - t * static_cast<double>(g) / static_cast<double>(w));
  return lines;
}

void check(const BoxSpec& spec) {
  double smallest = 1e300;
  for (int d = 0; d < 3; ++d) {
    if (!(spec.size[d] > 0.0)) throw Error("box mesh: every size must be > 0 m");
    if (spec.cells[d] < 1) throw Error("box mesh: every cell count must be >= 1");
    smallest = std::min(smallest, spec.size[d]);
  }
  if (spec.wall_thickness == 0.0) return;
  if (!(spec.wall_thickness > 0.0 && 2.0 * spec.wall_thickness < smallest))
    throw Error("box mesh: the wall thickness " + std::to_string(spec.wall_thickness) +
                " m must be > 0 and < half the smallest edge (" + std::to_string(smallest / 2) +
                " m), so that the cavity is not empty");
  if (spec.wall_cells < 1) throw Error("box mesh: the cells through the wall must be >= 1");
}

}  // namespace

Mesh make_box_mesh(const BoxSpec& spec) {
  check(spec);
  const bool hollow = spec.wall_thickness > 0.0;
  const long wall = hollow ? spec.wall_cells : 0;
  std::array<long, 3> cells{};
  detail::MaskedGrid grid;
  for (int d = 0; d < 3; ++d) {
    grid.lines[static_cast<std::size_t>(d)] = axis_lines(spec, d);
    cells[d] = spec.cells[d] + 2 * wall;
  }
  const auto in_cavity = [&](const detail::GridCell& c) {
    for (int d = 0; d < 3; ++d)
      if (!(wall > 0 && c[d] >= wall && c[d] < cells[d] - wall)) return false;
    return true;
  };
  grid.regions = {"all"};
  grid.region = [&](const detail::GridCell& c) { return in_cavity(c) ? -1 : 0; };
  static const std::array<std::string, 6> names = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  grid.faces = [&](const detail::GridCell&, int d, int upper, bool outside,
                   std::vector<std::string>& out) {
    if (outside) {
      out.push_back(names[static_cast<std::size_t>(2 * d + upper)]);
      return;
    }
    // the wall below the cavity along d faces the cavity's min side, and so on
    out.push_back("inner");
    out.push_back("inner_" + names[static_cast<std::size_t>(2 * d + 1 - upper)]);
  };
  return detail::make_masked_grid_mesh(grid, spec.element);
}

}  // namespace partita::fem
