#include "partita/fem/box_mesher.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include "partita/fem/element_topology.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

using GridIndex = std::array<long, 3>;

// Cells along one axis: a solid box has spec.cells[d] equal cells; a hollow box has wall_cells
// cells through each wall and spec.cells[d] across the cavity between them.
struct Axis {
  long cells = 0;             // along the whole edge
  long wall = 0;              // cells in each wall (0: solid)
  std::vector<double> coord;  // position of each lattice index 0 .. 2 cells [m]

  bool in_cavity(long cell) const { return wall > 0 && cell >= wall && cell < cells - wall; }
};

Axis make_axis(const BoxSpec& spec, int d) {
  Axis a;
  const double o = spec.origin[d], s = spec.size[d], t = spec.wall_thickness;
  const bool hollow = t > 0.0;
  a.wall = hollow ? spec.wall_cells : 0;
  a.cells = spec.cells[d] + 2L * a.wall;
  a.coord.resize(static_cast<std::size_t>(2 * a.cells + 1));
  // piecewise uniform: [o, o+t] in 2 wall steps, [o+t, o+s-t] in 2 cells[d], [o+s-t, o+s] in 2 wall
  for (long g = 0; g <= 2 * a.cells; ++g) {
    double x = 0.0;
    if (!hollow) {
      x = o + s * static_cast<double>(g) / (2.0 * static_cast<double>(a.cells));
    } else if (g <= 2 * a.wall) {
      x = o + t * static_cast<double>(g) / (2.0 * static_cast<double>(a.wall));
    } else if (g <= 2 * (a.cells - a.wall)) {
      x = o + t +
          (s - 2 * t) * static_cast<double>(g - 2 * a.wall) /
              (2.0 * static_cast<double>(spec.cells[d]));
    } else {
      x = o + s - t * static_cast<double>(2 * a.cells - g) / (2.0 * static_cast<double>(a.wall));
    }
    a.coord[static_cast<std::size_t>(g)] = x;
  }
  return a;
}

// Nodes live on a lattice twice as fine as the cells (so that edge midpoints of hexahedra and
// of the Kuhn tetrahedra are lattice points); only lattice points used by elements are created.
class Lattice {
 public:
  Lattice(const std::array<Axis, 3>& axes, Mesh& mesh) : axes_(axes), mesh_(mesh) {}
  std::size_t node(const GridIndex& g) {
    const long key = g[0] + (2L * axes_[0].cells + 1) * (g[1] + (2L * axes_[1].cells + 1) * g[2]);
    auto [it, inserted] = ids_.try_emplace(key, 0);
    if (inserted) {
      Vec3 x;
      for (int d = 0; d < 3; ++d) x[d] = axes_[d].coord[static_cast<std::size_t>(g[d])];
      it->second = mesh_.add_node(x);
      index_.push_back(g);
    }
    return it->second;
  }
  const GridIndex& index(std::size_t node) const { return index_[node]; }

 private:
  const std::array<Axis, 3>& axes_;
  Mesh& mesh_;
  std::unordered_map<long, std::size_t> ids_;
  std::vector<GridIndex> index_;
};

double signed_volume(const std::array<GridIndex, 4>& c) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int d = 0; d < 3; ++d) m(r, d) = static_cast<double>(c[r + 1][d] - c[0][d]);
  }
  return m.determinant();
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
  const std::array<Axis, 3> axes = {make_axis(spec, 0), make_axis(spec, 1), make_axis(spec, 2)};
  const bool hollow = spec.wall_thickness > 0.0;
  Mesh mesh;
  mesh.add_region("all");
  Lattice lattice(axes, mesh);
  const ElementType type = spec.element;
  const bool hex = type == ElementType::Hex8 || type == ElementType::Hex20;
  const auto edges = quadratic_edges(type);

  // corners of one cell in lattice units (Hex8 order)
  const std::array<GridIndex, 8> cube = {
      {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}}};
  // Kuhn split: for each axis permutation p, the tet (0, e_p0, e_p0 + e_p1, (1,1,1)).
  std::vector<std::array<GridIndex, 8>> corner_sets;
  if (hex) {
    corner_sets.push_back(cube);
  } else {
    std::array<int, 3> perm = {0, 1, 2};
    do {
      std::array<GridIndex, 4> t{};
      for (int k = 1; k < 4; ++k) {
        t[k] = t[k - 1];
        t[k][perm[k - 1]] += 2;
      }
      if (signed_volume(t) < 0) std::swap(t[1], t[2]);
      corner_sets.push_back({t[0], t[1], t[2], t[3]});
    } while (std::next_permutation(perm.begin(), perm.end()));
  }

  const std::array<std::string, 6> names = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  // Adds the local faces of element `el` (of cell `cell`) that lie on the box's outer planes or
  // on the cavity's surface: a local face lies on a cell face when all its nodes share the
  // lattice index of that cell face along one axis d; the cell across it is outside the box
  // (an outer face) or in the cavity (an inner face).
  auto add_boundary_faces = [&](const Element& el, const GridIndex& cell) {
    for (int f = 0; f < local_face_count(type); ++f) {
      const auto local = local_face_nodes(type, f);
      for (int d = 0; d < 3; ++d) {
        const long g0 = lattice.index(el.nodes[local[0]])[d];
        const bool flat = std::all_of(local.begin(), local.end(),
                                      [&](int a) { return lattice.index(el.nodes[a])[d] == g0; });
        if (!flat || (g0 != 2 * cell[d] && g0 != 2 * cell[d] + 2)) continue;
        const int upper = g0 == 2 * cell[d] + 2 ? 1 : 0;
        GridIndex across = cell;
        across[d] += upper ? 1 : -1;
        std::array<std::size_t, kMaxFaceNodes> ids{};
        for (std::size_t a = 0; a < local.size(); ++a) ids[a] = el.nodes[local[a]];
        const std::span<const std::size_t> span{ids.data(), local.size()};
        if (across[d] < 0 || across[d] >= axes[d].cells) {
          mesh.add_face_element(names[2 * d + upper], local_face_type(type, f), span);
        } else if (axes[0].in_cavity(across[0]) && axes[1].in_cavity(across[1]) &&
                   axes[2].in_cavity(across[2])) {
          // the wall below the cavity along d faces the cavity's min side, and so on
          mesh.add_face_element("inner", local_face_type(type, f), span);
          mesh.add_face_element("inner_" + names[2 * d + (1 - upper)], local_face_type(type, f),
                                span);
        }
        break;
      }
    }
  };

  for (long k = 0; k < axes[2].cells; ++k) {
    for (long j = 0; j < axes[1].cells; ++j) {
      for (long i = 0; i < axes[0].cells; ++i) {
        if (axes[0].in_cavity(i) && axes[1].in_cavity(j) && axes[2].in_cavity(k)) continue;
        const GridIndex base = {2 * i, 2 * j, 2 * k};
        for (const auto& cs : corner_sets) {
          std::array<GridIndex, kMaxElementNodes> g{};
          const int nc = corner_count(type);
          for (int a = 0; a < nc; ++a) {
            for (int d = 0; d < 3; ++d) g[a][d] = base[d] + cs[a][d];
          }
          for (std::size_t e = 0; e < edges.size(); ++e) {
            for (int d = 0; d < 3; ++d) {
              g[nc + e][d] = (g[edges[e][0]][d] + g[edges[e][1]][d]) / 2;
            }
          }
          std::array<std::size_t, kMaxElementNodes> ids{};
          for (int a = 0; a < node_count(type); ++a) ids[a] = lattice.node(g[a]);
          const std::size_t e =
              mesh.add_element(type, {ids.data(), static_cast<std::size_t>(node_count(type))}, 0);
          add_boundary_faces(mesh.element(e), {i, j, k});
        }
      }
    }
  }

  // Named node sets.
  std::vector<std::size_t> all(mesh.num_nodes());
  for (std::size_t n = 0; n < all.size(); ++n) all[n] = n;
  mesh.add_node_set("all", all);
  for (int side = 0; side < 6; ++side) {
    const int d = side / 2;
    const long plane = (side % 2 == 0) ? 0 : 2L * axes[d].cells;
    std::vector<std::size_t> ids;
    for (std::size_t n = 0; n < mesh.num_nodes(); ++n) {
      if (lattice.index(n)[d] == plane) ids.push_back(n);
    }
    mesh.add_node_set(names[side], ids);
  }
  if (hollow) mesh.add_node_set("inner", mesh.face_nodes("inner"));
  return mesh;
}

}  // namespace partita::fem
