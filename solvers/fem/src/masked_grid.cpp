#include "masked_grid.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <unordered_map>

#include "partita/fem/element_topology.hpp"

namespace partita::fem::detail {
namespace {

// Nodes live on a lattice twice as fine as the cells (so that edge midpoints of hexahedra and
// of the Kuhn tetrahedra are lattice points); only lattice points used by elements are created.
class Lattice {
 public:
  Lattice(const std::array<std::vector<double>, 3>& lines, Mesh& mesh) : mesh_(mesh) {
    for (int d = 0; d < 3; ++d) {
      const auto& l = lines[static_cast<std::size_t>(d)];
      auto& c = coord_[static_cast<std::size_t>(d)];
      c.resize(2 * l.size() - 1);
      for (std::size_t g = 0; g < l.size(); ++g) c[2 * g] = l[g];
      for (std::size_t g = 0; g + 1 < l.size(); ++g) c[2 * g + 1] = 0.5 * (l[g] + l[g + 1]);
    }
  }
  std::size_t node(const GridCell& g) {
    const long key = g[0] + static_cast<long>(coord_[0].size()) *
                                (g[1] + static_cast<long>(coord_[1].size()) * g[2]);
    auto [it, inserted] = ids_.try_emplace(key, 0);
    if (inserted) {
      Vec3 x;
      for (int d = 0; d < 3; ++d)
        x[d] = coord_[static_cast<std::size_t>(d)][static_cast<std::size_t>(g[d])];
      it->second = mesh_.add_node(x);
      index_.push_back(g);
    }
    return it->second;
  }
  const GridCell& index(std::size_t node) const { return index_[node]; }

 private:
  std::array<std::vector<double>, 3> coord_;  // position of each lattice index [m]
  Mesh& mesh_;
  std::unordered_map<long, std::size_t> ids_;
  std::vector<GridCell> index_;
};

double signed_volume(const std::array<GridCell, 4>& c) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int d = 0; d < 3; ++d) m(r, d) = static_cast<double>(c[r + 1][d] - c[0][d]);
  }
  return m.determinant();
}

// Corners of the elements of one cell in lattice units: the cube (Hex8 order), or for each axis
// permutation p the Kuhn tetrahedron (0, e_p0, e_p0 + e_p1, (1,1,1)).
std::vector<std::array<GridCell, 8>> cell_corner_sets(bool hex) {
  const std::array<GridCell, 8> cube = {
      {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}}};
  std::vector<std::array<GridCell, 8>> sets;
  if (hex) {
    sets.push_back(cube);
    return sets;
  }
  std::array<int, 3> perm = {0, 1, 2};
  do {
    std::array<GridCell, 4> t{};
    for (int k = 1; k < 4; ++k) {
      t[k] = t[k - 1];
      t[k][perm[k - 1]] += 2;
    }
    if (signed_volume(t) < 0) std::swap(t[1], t[2]);
    sets.push_back({t[0], t[1], t[2], t[3]});
  } while (std::next_permutation(perm.begin(), perm.end()));
  return sets;
}

}  // namespace

Mesh make_masked_grid_mesh(const MaskedGrid& grid, ElementType type) {
  std::array<long, 3> cells{};
  for (int d = 0; d < 3; ++d)
    cells[d] = static_cast<long>(grid.lines[static_cast<std::size_t>(d)].size()) - 1;
  Mesh mesh;
  for (const auto& r : grid.regions) mesh.add_region(r);
  Lattice lattice(grid.lines, mesh);
  const bool hex = type == ElementType::Hex8 || type == ElementType::Hex20;
  const auto edges = quadratic_edges(type);
  const auto corner_sets = cell_corner_sets(hex);
  const auto solid = [&](const GridCell& c) {
    for (int d = 0; d < 3; ++d)
      if (c[d] < 0 || c[d] >= cells[d]) return false;
    return grid.region(c) >= 0;
  };

  // Adds the local faces of element `el` (of cell `cell`) that lie on the boundary of the solid:
  // a local face lies on a cell face when all its nodes share the lattice index of that cell
  // face along one axis d; it is a boundary face when the cell across is empty or outside.
  std::vector<std::string> names;
  auto add_boundary_faces = [&](const Element& el, const GridCell& cell) {
    for (int f = 0; f < local_face_count(type); ++f) {
      const auto local = local_face_nodes(type, f);
      for (int d = 0; d < 3; ++d) {
        const long g0 = lattice.index(el.nodes[local[0]])[d];
        const bool flat = std::all_of(local.begin(), local.end(),
                                      [&](int a) { return lattice.index(el.nodes[a])[d] == g0; });
        if (!flat || (g0 != 2 * cell[d] && g0 != 2 * cell[d] + 2)) continue;
        const int upper = g0 == 2 * cell[d] + 2 ? 1 : 0;
        GridCell across = cell;
        across[d] += upper ? 1 : -1;
        if (!solid(across)) {
          names.clear();
          grid.faces(cell, d, upper, across[d] < 0 || across[d] >= cells[d], names);
          std::array<std::size_t, kMaxFaceNodes> ids{};
          for (std::size_t a = 0; a < local.size(); ++a) ids[a] = el.nodes[local[a]];
          const std::span<const std::size_t> span{ids.data(), local.size()};
          for (const auto& n : names) mesh.add_face_element(n, local_face_type(type, f), span);
        }
        break;
      }
    }
  };

  for (long k = 0; k < cells[2]; ++k) {
    for (long j = 0; j < cells[1]; ++j) {
      for (long i = 0; i < cells[0]; ++i) {
        const int region = grid.region({i, j, k});
        if (region < 0) continue;
        const GridCell base = {2 * i, 2 * j, 2 * k};
        for (const auto& cs : corner_sets) {
          std::array<GridCell, kMaxElementNodes> g{};
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
          const std::size_t e = mesh.add_element(
              type, {ids.data(), static_cast<std::size_t>(node_count(type))}, region);
          add_boundary_faces(mesh.element(e), {i, j, k});
        }
      }
    }
  }

  std::vector<std::size_t> all(mesh.num_nodes());
  for (std::size_t n = 0; n < all.size(); ++n) all[n] = n;
  mesh.add_node_set("all", all);
  for (const auto& name : mesh.face_names()) mesh.add_node_set(name, mesh.face_nodes(name));
  return mesh;
}

}  // namespace partita::fem::detail
