#include "partita/dem/neighbor_list.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/parallel.hpp"

#include "parallel_pass.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace partita::dem {

int NeighborList::Grid::coord(double x, double o, int n) const {
  const double c = std::floor((x - o) * inv_cell);
  if (!(c >= 0.0)) return 0;  // also NaN
  return c >= n - 1 ? n - 1 : static_cast<int>(c);
}

std::array<int, 3> NeighborList::Grid::coords(const Eigen::Vector3d& x) const {
  return {coord(x.x(), origin.x(), nx), coord(x.y(), origin.y(), ny), coord(x.z(), origin.z(), nz)};
}

void NeighborList::clear() {
  valid_ = false;
  offsets_.assign(1, 0);
  neighbors_.clear();
  slot_source_.clear();
  plane_mask_.clear();
  mesh_offsets_.assign(1, 0);
  mesh_candidates_.clear();
}

bool NeighborList::needs_rebuild(const Particles& p, const std::vector<PlaneWall>& planes,
                                 const std::vector<TriangleMesh>& meshes) const {
  if (!valid_ || position_at_build_.size() != p.size()) return true;
  const long n = static_cast<long>(p.size());
  double max2 = 0.0;
#pragma omp parallel for reduction(max : max2) schedule(static) if (n >= 1024)
  for (long i = 0; i < n; ++i)
    max2 = std::max(max2, (p.position[i] - position_at_build_[i]).squaredNorm());
  return needs_rebuild(max2, planes, meshes);
}

bool NeighborList::needs_rebuild(double max_moved2, const std::vector<PlaneWall>& planes,
                                 const std::vector<TriangleMesh>& meshes) const {
  if (!valid_ || plane_at_build_.size() != planes.size()) return true;
  const double limit2 = 0.25 * skin_ * skin_;
  if (max_moved2 > limit2) return true;
  for (std::size_t k = 0; k < planes.size(); ++k)
    if ((planes[k].point - plane_at_build_[k]).squaredNorm() > limit2) return true;
  for (const TriangleMesh& m : meshes) {
    const int nv = m.vertex_count();
    auto moved2 = [&](int v) { return (m.position_[v] - m.position_at_build_[v]).squaredNorm(); };
    if (nv < parallel_pass_min) {  // (a step's test: no parallel construct for small meshes)
      for (int v = 0; v < nv; ++v)
        if (moved2(v) > limit2) return true;
      continue;
    }
    double most2 = 0.0;  // the largest vertex motion since the build: exact in any order
#pragma omp parallel for schedule(static) reduction(max : most2)
    for (int v = 0; v < nv; ++v) most2 = std::max(most2, moved2(v));
    if (most2 > limit2) return true;
  }
  return false;
}

void NeighborList::renumber(const std::vector<int>& new_of_old) {
  renumber(new_of_old, static_cast<int>(new_of_old.size()));
}

void NeighborList::renumber(const std::vector<int>& new_of_old, int n) {
  const int rows = static_cast<int>(offsets_.size()) - 1;  // particles added since: no rows
  if (!valid_ || rows > static_cast<int>(new_of_old.size())) {
    clear();
    return;
  }
  // Each pair (i, j) becomes (min(a, b), max(a, b)) with a = new(i), b = new(j); its source
  // remembers the old slot and whether a > b (a history of the first particle relative to the
  // second changes sign). Pairs with a removed particle are dropped.
  new_offsets_.assign(n + 1, 0);
  for (int i = 0; i < rows; ++i) {
    if (new_of_old[i] < 0) continue;
    for (int s = offsets_[i]; s < offsets_[i + 1]; ++s)
      if (new_of_old[neighbors_[s]] >= 0)
        ++new_offsets_[std::min(new_of_old[i], new_of_old[neighbors_[s]]) + 1];
  }
  for (int i = 0; i < n; ++i) new_offsets_[i + 1] += new_offsets_[i];
  new_neighbors_.resize(new_offsets_[n]);
  slot_source_.resize(new_offsets_[n]);
  counts_.assign(n, 0);
  for (int i = 0; i < rows; ++i) {
    if (new_of_old[i] < 0) continue;
    for (int s = offsets_[i]; s < offsets_[i + 1]; ++s) {
      const int a = new_of_old[i], b = new_of_old[neighbors_[s]];
      if (b < 0) continue;
      const int row = std::min(a, b);
      const int slot = new_offsets_[row] + counts_[row]++;
      new_neighbors_[slot] = std::max(a, b);
      slot_source_[slot] = {s, a > b};
    }
  }
  // rows sorted by neighbour (short rows: insertion sort, sources moved along)
  for (int r = 0; r < n; ++r)
    for (int s = new_offsets_[r] + 1; s < new_offsets_[r + 1]; ++s)
      for (int t = s; t > new_offsets_[r] && new_neighbors_[t - 1] > new_neighbors_[t]; --t) {
        std::swap(new_neighbors_[t - 1], new_neighbors_[t]);
        std::swap(slot_source_[t - 1], slot_source_[t]);
      }
  offsets_.swap(new_offsets_);
  neighbors_.swap(new_neighbors_);
  // the build positions are only compared with the same particle's: drop them (next build sets
  // them); the lists must be rebuilt before use
  position_at_build_.clear();
}

void NeighborList::write_rows(BinaryWriter& out) const {
  out.value(skin_);
  out.value(builds_);
  out.value(static_cast<char>(valid_));
  out.array(offsets_);
  out.array(neighbors_);
}

void NeighborList::write_build_references(BinaryWriter& out) const {
  out.array(position_at_build_);
  out.array(plane_at_build_);
  out.array(plane_mask_);
  out.array(mesh_offsets_);
  out.array(mesh_candidates_);
}

void NeighborList::read_rows(BinaryReader& in) {
  in.value(skin_, "neighbour skin");
  in.value(builds_, "neighbour build count");
  valid_ = in.value<char>("neighbour list validity") != 0;
  in.array(offsets_, "neighbour offsets");
  in.array(neighbors_, "neighbour pairs");
  if (offsets_.empty() || static_cast<std::size_t>(offsets_.back()) != neighbors_.size())
    throw Error("corrupt state: neighbour list arrays do not agree");
  slot_source_.clear();  // the per-pair state comes with the state
}

void NeighborList::read_build_references(BinaryReader& in) {
  in.array(position_at_build_, "positions at the list build");
  in.array(plane_at_build_, "planes at the list build");
  in.array(plane_mask_, "plane masks");
  in.array(mesh_offsets_, "mesh candidate offsets");
  in.array(mesh_candidates_, "mesh candidates");
}

void NeighborList::throw_absurd_extent(const Particles& p, const Eigen::Vector3d& lo,
                                       const Eigen::Vector3d& hi, double natural, double cell) {
  const std::size_t n = p.size();
  std::ostringstream msg;
  msg.precision(6);
  // the particle to name: the first with a non-finite coordinate, else the one farthest from the
  // particles' mean along the axis of the largest extent (the odd one out)
  std::size_t worst = n;
  for (std::size_t i = 0; i < n && worst == n; ++i)
    if (!p.position[i].allFinite()) worst = i;
  if (worst < n) {
    msg << "particle id " << p.id[worst] << " (index " << worst << ") is at "
        << vector_text(p.position[worst])
        << ": a position that is not a finite number (a corrupt state, or a step that diverged)";
    throw Error(msg.str());
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += p.position[i][axis] / static_cast<double>(n);
  worst = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (std::abs(p.position[i][axis] - mean) > std::abs(p.position[worst][axis] - mean)) worst = i;
  msg << "the particles span " << vector_text(lo) << " .. " << vector_text(hi) << " m, "
      << (hi - lo).maxCoeff() / natural << " neighbour cells of " << natural
      << " m (2 R_max + skin) along the widest axis";
  if (cell > 0.0)
    msg << "; with the cell count capped at 4 N + 64 (memory in proportion to the " << n
        << " particles) the cells grow to " << cell
        << " m and the neighbour search would compare nearly every pair";
  msg << ": particle id " << p.id[worst] << " (index " << worst << ") at "
      << vector_text(p.position[worst])
      << " m lies far from the others (a unit slip in a particle file, e.g. mm read as m, or a "
         "corrupt state)";
  throw Error(msg.str());
}

// Calls visit(j) for every j > i within R_i + R_j + skin of i, cells in a fixed order.
template <class Visit>
void NeighborList::visit_pairs(const Particles& p, int i, Visit&& visit) const {
  const Eigen::Vector3d& xi = p.position[i];
  const double ri = p.radius[i] + skin_;
  const char* const passive = passive_ && (*passive_)[i] ? passive_->data() : nullptr;
  const auto c = grid_.coords(xi);
  const int z0 = std::max(c[2] - 1, 0), z1 = std::min(c[2] + 1, grid_.nz - 1);
  const int y0 = std::max(c[1] - 1, 0), y1 = std::min(c[1] + 1, grid_.ny - 1);
  const int x0 = std::max(c[0] - 1, 0), x1 = std::min(c[0] + 1, grid_.nx - 1);
  for (int iz = z0; iz <= z1; ++iz)
    for (int iy = y0; iy <= y1; ++iy) {
      const int first = cell_start_[grid_.index(x0, iy, iz)];
      const int last = cell_start_[grid_.index(x1, iy, iz) + 1];
      for (int k = first; k < last; ++k) {
        const int j = cell_items_[k];
        if (j <= i || (passive && passive[j])) continue;
        const double cut = ri + p.radius[j];
        if ((p.position[j] - xi).squaredNorm() < cut * cut) visit(j);
      }
    }
}

void NeighborList::build(const Particles& p, const std::vector<PlaneWall>& planes,
                         std::vector<TriangleMesh>& meshes) {
  search(p, planes, meshes);
  for (TriangleMesh& m : meshes) m.position_at_build_ = m.position_;
}

void NeighborList::search(const Particles& p, const std::vector<PlaneWall>& planes,
                          const std::vector<TriangleMesh>& meshes) {
  ++builds_;
  const int n = static_cast<int>(p.size());
  if (passive_ && passive_->size() != p.size())
    throw Error("neighbor list: " + std::to_string(passive_->size()) +
                " passive flags for " + std::to_string(n) + " particles");
  // Grid over the particles' bounding box, cells 2 R_max + skin wide (at most ~4 N cells).
  // (the passes over every particle below run on the threads for large beds; minima, maxima and
  // per-particle results are the same in any order)
  const double big = std::numeric_limits<double>::max();
  double lx = big, ly = big, lz = big, hx = -big, hy = -big, hz = -big, r_max = 0.0;
#pragma omp parallel for schedule(static) if (n >= parallel_pass_min) \
    reduction(min : lx, ly, lz) reduction(max : hx, hy, hz, r_max)
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& x = p.position[i];
    lx = std::min(lx, x.x()), ly = std::min(ly, x.y()), lz = std::min(lz, x.z());
    hx = std::max(hx, x.x()), hy = std::max(hy, x.y()), hz = std::max(hz, x.z());
    r_max = std::max(r_max, p.radius[i]);
  }
  Eigen::Vector3d lo(lx, ly, lz), hi(hx, hy, hz);
  if (n == 0) lo = hi = Eigen::Vector3d::Zero();
  const double natural = std::max(2.0 * r_max + skin_, 1e-12);
  double cell = natural;
  const Eigen::Vector3d extent = hi - lo;
  // (a NaN coordinate is left out of the box above and binned into cell 0; an infinite one, or
  // a box too large for doubles, cannot be gridded: the state is corrupt or the step diverged)
  if (!extent.allFinite()) throw_absurd_extent(p, lo, hi, natural, 0.0);
  // The cell count is capped at max_cells (memory in proportion to the particles, whatever the
  // extent: one particle 880 m away from a bed of millimetre grains would ask for 10^17 cells);
  // above it the cells grow. Counted in doubles (no integer overflow), so the cap always holds.
  auto dims = [&](double h, int k) { return std::floor(extent[k] / h) + 1.0; };
  const double max_cells = 4.0 * n + 64.0;
  while (dims(cell, 0) * dims(cell, 1) * dims(cell, 2) > max_cells) cell *= 1.26;
  grid_.origin = lo;
  grid_.inv_cell = 1.0 / cell;
  grid_.nx = static_cast<int>(dims(cell, 0)), grid_.ny = static_cast<int>(dims(cell, 1)),
  grid_.nz = static_cast<int>(dims(cell, 2));

  // Counting sort of the particles into cells (ascending index within a cell). The cell arrays
  // get room for the most cells at once, so a growing grid does not reallocate them.
  particle_cell_.resize(n);
  cell_start_.reserve(static_cast<std::size_t>(max_cells) + 1);
  counts_.reserve(std::max(static_cast<std::size_t>(max_cells), static_cast<std::size_t>(n)) + 1);
  if (!meshes.empty()) tri_cell_start_.reserve(static_cast<std::size_t>(max_cells) + 1);
  cell_start_.assign(grid_.cells() + 1, 0);
  detail::parallel_pass(n, [&](int i) {
    const auto c = grid_.coords(p.position[i]);
    particle_cell_[i] = grid_.index(c[0], c[1], c[2]);
  });
  for (int i = 0; i < n; ++i) ++cell_start_[particle_cell_[i] + 1];
  if (cell > natural && n >= kDegenerateMinParticles) {
    // The cap grew the cells (a sparse or stretched cloud): the search visits about 27 sum_c n_c^2
    // candidates. Far beyond the dense bed's few per particle (a bed gathered into a handful of
    // cells by one particle far away), a build would take hours: the extent is absurd.
    double visits = 0.0;
    for (int c = 0; c < grid_.cells(); ++c)
      visits += static_cast<double>(cell_start_[c + 1]) * cell_start_[c + 1];
    if (visits > kDegenerateVisits * n) throw_absurd_extent(p, lo, hi, natural, cell);
  }
  for (int c = 0; c < grid_.cells(); ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  counts_.assign(grid_.cells(), 0);
  for (int i = 0; i < n; ++i) {
    const int c = particle_cell_[i];
    cell_items_[cell_start_[c] + counts_[c]++] = i;
  }

  // Half list in two passes (count, fill), each row sorted by j.
  new_offsets_.resize(n + 1);
  new_offsets_[0] = 0;
#pragma omp parallel for schedule(dynamic, 64) if (n >= 1024)
  for (int i = 0; i < n; ++i) {
    int count = 0;
    visit_pairs(p, i, [&](int) { ++count; });
    new_offsets_[i + 1] = count;
  }
  for (int i = 0; i < n; ++i) new_offsets_[i + 1] += new_offsets_[i];
  new_neighbors_.resize(new_offsets_[n]);
  slot_source_.resize(new_offsets_[n]);
  // rows of the previous build (particles added since then have none)
  const int old_n = valid_ ? std::min(n, static_cast<int>(offsets_.size()) - 1) : 0;
#pragma omp parallel for schedule(dynamic, 64) if (n >= 1024)
  for (int i = 0; i < n; ++i) {
    int* row = new_neighbors_.data() + new_offsets_[i];
    int k = 0;
    visit_pairs(p, i, [&](int j) { row[k++] = j; });
    std::sort(row, row + k);
    // the old slots of pairs that were already listed (both rows sorted)
    int o = i < old_n ? offsets_[i] : 0;
    const int o_end = i < old_n ? offsets_[i + 1] : 0;
    for (int m = 0; m < k; ++m) {
      while (o < o_end && neighbors_[o] < row[m]) ++o;
      slot_source_[new_offsets_[i] + m] = {(o < o_end && neighbors_[o] == row[m]) ? o : -1, false};
    }
  }
  offsets_.swap(new_offsets_);
  neighbors_.swap(new_neighbors_);

  position_at_build_.resize(p.position.size());
  detail::parallel_pass(n, [&](int i) { position_at_build_[i] = p.position[i]; });
  // Planes within R + skin of each particle.
  plane_at_build_.resize(planes.size());
  for (std::size_t k = 0; k < planes.size(); ++k) plane_at_build_[k] = planes[k].point;
  plane_mask_.resize(n);
  const int np = static_cast<int>(planes.size());
  detail::parallel_pass(n, [&](int i) {
    std::uint64_t mask = 0;
    if (passive_ && (*passive_)[i]) {
      // (none)
    } else if (np > 64) {
      mask = ~std::uint64_t{0};
    } else {
      for (int k = 0; k < np; ++k)
        if ((p.position[i] - planes[k].point).dot(planes[k].normal) < p.radius[i] + skin_)
          mask |= std::uint64_t{1} << k;
    }
    plane_mask_[i] = mask;
  });
  build_mesh_candidates(p, meshes, r_max);
  valid_ = true;
}

void NeighborList::build_mesh_candidates(const Particles& p,
                                         const std::vector<TriangleMesh>& meshes, double r_max) {
  const int n = static_cast<int>(p.size());
  mesh_candidates_.clear();
  if (meshes.empty()) {  // no offsets per particle either
    mesh_offsets_.assign(1, 0);
    return;
  }
  mesh_offsets_.assign(n + 1, 0);
  const double grow = r_max + skin_;
  const double cell = 1.0 / grid_.inv_cell;
  const Eigen::Vector3d grid_hi =
      grid_.origin + cell * Eigen::Vector3d(grid_.nx, grid_.ny, grid_.nz);
  // Bin every triangle into the cells its box (grown by R_max + skin) overlaps; two passes.
  tri_cell_start_.assign(grid_.cells() + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      for (int c = 0; c < grid_.cells(); ++c) tri_cell_start_[c + 1] += tri_cell_start_[c];
      tri_cell_items_.resize(tri_cell_start_[grid_.cells()]);
      counts_.assign(grid_.cells(), 0);
    }
    for (int m = 0; m < static_cast<int>(meshes.size()); ++m) {
      const TriangleMesh& mesh = meshes[m];
      for (int t = 0; t < mesh.triangle_count(); ++t) {
        const auto& tri = mesh.triangle(t);
        Eigen::Vector3d blo = mesh.position_[tri[0]], bhi = blo;
        for (int k = 1; k < 3; ++k) {
          blo = blo.cwiseMin(mesh.position_[tri[k]]);
          bhi = bhi.cwiseMax(mesh.position_[tri[k]]);
        }
        blo.array() -= grow;
        bhi.array() += grow;
        if ((blo.array() > grid_hi.array()).any() || (bhi.array() < grid_.origin.array()).any())
          continue;
        const auto c0 = grid_.coords(blo), c1 = grid_.coords(bhi);
        for (int iz = c0[2]; iz <= c1[2]; ++iz)
          for (int iy = c0[1]; iy <= c1[1]; ++iy)
            for (int ix = c0[0]; ix <= c1[0]; ++ix) {
              const int c = grid_.index(ix, iy, iz);
              if (pass == 0)
                ++tri_cell_start_[c + 1];
              else
                tri_cell_items_[tri_cell_start_[c] + counts_[c]++] = {m, t};
            }
      }
    }
  }
  // Each particle keeps the triangles of its own cell within R + skin (two passes).
  auto visit = [&](int i, auto&& keep) {
    if (passive_ && (*passive_)[i]) return;
    const int c = particle_cell_[i];
    const double cut = p.radius[i] + skin_;
    for (int k = tri_cell_start_[c]; k < tri_cell_start_[c + 1]; ++k) {
      const MeshCandidate mc = tri_cell_items_[k];
      const auto cp = meshes[mc.mesh].closest_point(mc.triangle, p.position[i]);
      if ((cp.point - p.position[i]).squaredNorm() < cut * cut) keep(mc);
    }
  };
#pragma omp parallel for schedule(dynamic, 64) if (n >= 1024)
  for (int i = 0; i < n; ++i) {
    int count = 0;
    visit(i, [&](MeshCandidate) { ++count; });
    mesh_offsets_[i + 1] = count;
  }
  for (int i = 0; i < n; ++i) mesh_offsets_[i + 1] += mesh_offsets_[i];
  // (the candidates of a bed's surface layer fluctuate: room for half as many again)
  const auto total = static_cast<std::size_t>(mesh_offsets_[n]);
  if (mesh_candidates_.capacity() < total) mesh_candidates_.reserve(total + total / 2);
  mesh_candidates_.resize(total);
#pragma omp parallel for schedule(dynamic, 64) if (n >= 1024)
  for (int i = 0; i < n; ++i) {
    int k = mesh_offsets_[i];
    visit(i, [&](MeshCandidate mc) { mesh_candidates_[k++] = mc; });
  }
}

}  // namespace partita::dem
