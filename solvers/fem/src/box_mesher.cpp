#include "partita/fem/box_mesher.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <unordered_map>

#include "partita/fem/element_topology.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

using GridIndex = std::array<long, 3>;

// Nodes live on a lattice twice as fine as the cells (so that edge midpoints of hexahedra and
// of the Kuhn tetrahedra are lattice points); only lattice points used by elements are created.
class Lattice {
 public:
  Lattice(const BoxSpec& spec, Mesh& mesh) : spec_(spec), mesh_(mesh) {}
  std::size_t node(const GridIndex& g) {
    const long key = g[0] + (2L * spec_.cells[0] + 1) * (g[1] + (2L * spec_.cells[1] + 1) * g[2]);
    auto [it, inserted] = ids_.try_emplace(key, 0);
    if (inserted) {
      Vec3 x;
      for (int d = 0; d < 3; ++d) {
        x[d] = spec_.origin[d] + spec_.size[d] * static_cast<double>(g[d]) / (2.0 * spec_.cells[d]);
      }
      it->second = mesh_.add_node(x);
      index_.push_back(g);
    }
    return it->second;
  }
  const GridIndex& index(std::size_t node) const { return index_[node]; }

 private:
  const BoxSpec& spec_;
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

}  // namespace

Mesh make_box_mesh(const BoxSpec& spec) {
  for (int d = 0; d < 3; ++d) {
    if (!(spec.size[d] > 0.0)) throw Error("box mesh: every size must be > 0 m");
    if (spec.cells[d] < 1) throw Error("box mesh: every cell count must be >= 1");
  }
  Mesh mesh;
  mesh.add_region("all");
  Lattice lattice(spec, mesh);
  const ElementType type = spec.element;
  const bool hex = type == ElementType::Hex8 || type == ElementType::Hex20;
  const auto edges = quadratic_edges(type);

  // corners of one cell in lattice units (Hex8 order)
  const std::array<GridIndex, 8> cube = {
      {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}}};
  // Kuhn split: for each axis permutation p, the tet (0, e_p0, e_p0 + e_p1, (1,1,1)).
  std::vector<std::array<GridIndex, 4>> tets;
  std::array<int, 3> perm = {0, 1, 2};
  do {
    std::array<GridIndex, 4> t{};
    for (int k = 1; k < 4; ++k) {
      t[k] = t[k - 1];
      t[k][perm[k - 1]] += 2;
    }
    if (signed_volume(t) < 0) std::swap(t[1], t[2]);
    tets.push_back(t);
  } while (std::next_permutation(perm.begin(), perm.end()));

  for (long k = 0; k < spec.cells[2]; ++k) {
    for (long j = 0; j < spec.cells[1]; ++j) {
      for (long i = 0; i < spec.cells[0]; ++i) {
        const GridIndex base = {2 * i, 2 * j, 2 * k};
        std::vector<std::array<GridIndex, 8>> corner_sets;
        if (hex) {
          corner_sets.push_back(cube);
        } else {
          for (const auto& t : tets) corner_sets.push_back({t[0], t[1], t[2], t[3]});
        }
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
          mesh.add_element(type, {ids.data(), static_cast<std::size_t>(node_count(type))}, 0);
        }
      }
    }
  }

  // Named faces: local element faces whose nodes all lie on one boundary plane.
  const std::array<std::string, 6> names = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  for (const auto& el : mesh.elements()) {
    for (int f = 0; f < local_face_count(type); ++f) {
      const auto local = local_face_nodes(type, f);
      for (int side = 0; side < 6; ++side) {
        const int d = side / 2;
        const long plane = (side % 2 == 0) ? 0 : 2L * spec.cells[d];
        const bool on = std::all_of(local.begin(), local.end(),
                                    [&](int a) { return lattice.index(el.nodes[a])[d] == plane; });
        if (on) {
          std::array<std::size_t, kMaxFaceNodes> ids{};
          for (std::size_t a = 0; a < local.size(); ++a) ids[a] = el.nodes[local[a]];
          mesh.add_face_element(names[side], local_face_type(type, f), {ids.data(), local.size()});
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
    const long plane = (side % 2 == 0) ? 0 : 2L * spec.cells[d];
    std::vector<std::size_t> ids;
    for (std::size_t n = 0; n < mesh.num_nodes(); ++n) {
      if (lattice.index(n)[d] == plane) ids.push_back(n);
    }
    mesh.add_node_set(names[side], ids);
  }
  return mesh;
}

}  // namespace partita::fem
