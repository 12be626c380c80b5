#include "partita/dem/packing_generator.hpp"

#include "partita/dem/error.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace partita::dem {

namespace {

// SplitMix64: small, fast, identical on every platform (unlike std:: distributions).
struct Random {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

}  // namespace

Packing PackingGenerator::generate(const PackingSpec& spec) {
  std::ostringstream msg;
  const Eigen::Vector3d size = spec.hi - spec.lo;
  const std::size_t nk = spec.diameters.size();
  if (nk == 0 || spec.fractions.size() != nk)
    msg << "packing: need one fraction per diameter, got " << nk << " diameters and "
        << spec.fractions.size() << " fractions";
  else if (!(spec.porosity > 0.3 && spec.porosity < 1.0))
    msg << "packing: porosity must be in (0.3, 1) for this generator, got " << spec.porosity;
  else if (!(spec.max_overlap > 0.0))
    msg << "packing: max_overlap must be > 0, got " << spec.max_overlap;
  for (std::size_t k = 0; k < nk && msg.str().empty(); ++k) {
    if (!(spec.diameters[k] > 0.0))
      msg << "packing: diameter " << k << " must be > 0 m, got " << spec.diameters[k];
    else if (!(spec.fractions[k] >= 0.0))
      msg << "packing: fraction " << k << " must be >= 0, got " << spec.fractions[k];
    else if (!(size.minCoeff() > spec.diameters[k]))
      msg << "packing: diameter " << spec.diameters[k] << " m does not fit in the box of size ("
          << size.x() << ", " << size.y() << ", " << size.z() << ") m";
  }
  if (!msg.str().empty()) throw Error(msg.str());

  // Counts: number fractions p_k (mass fractions / d^3 for the mass basis), N = V_s / sum p_k V_k.
  std::vector<double> p(nk), vol(nk);
  double psum = 0.0;
  for (std::size_t k = 0; k < nk; ++k) {
    const double d = spec.diameters[k];
    vol[k] = std::numbers::pi / 6.0 * d * d * d;
    p[k] =
        spec.basis == PackingSpec::Basis::number ? spec.fractions[k] : spec.fractions[k] / vol[k];
    psum += p[k];
  }
  if (!(psum > 0.0)) throw Error("packing: all fractions are zero");
  const double box_volume = size.prod();
  const double solid = (1.0 - spec.porosity) * box_volume;
  double mean_vol = 0.0;
  for (std::size_t k = 0; k < nk; ++k) mean_vol += p[k] / psum * vol[k];
  const double n_total = solid / mean_vol;
  std::vector<double> radii;
  for (std::size_t k = 0; k < nk; ++k) {
    const long count = std::lround(n_total * p[k] / psum);
    radii.insert(radii.end(), count, 0.5 * spec.diameters[k]);
  }
  const int n = static_cast<int>(radii.size());
  if (n == 0) throw Error("packing: the box is too small for a single sphere at this porosity");
  Random rng{spec.seed};
  for (int i = n - 1; i > 0; --i) std::swap(radii[i], radii[rng.next() % (i + 1)]);

  const double r_min = *std::min_element(radii.begin(), radii.end());
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const double bound = spec.max_overlap * r_min;
  const double margin = 5.0 * bound;  // push pairs a little apart: converges faster
  // Neighbour-list skin: pairs closer than r_i + r_j + skin are listed; the list is rebuilt when
  // a sphere has moved by half of it. Cells of size 2 R_max + skin over the box (particles never
  // leave it): a listed pair lies in adjacent cells.
  const double skin = std::max(2.0 * r_min, 4.0 * margin);
  const double cell = 2.0 * r_max + skin;
  int dims[3];
  for (int a = 0; a < 3; ++a) dims[a] = std::max(1, static_cast<int>(size[a] / cell));
  const int ncell = dims[0] * dims[1] * dims[2];
  auto coord = [&](double v, int a) {
    const int c = static_cast<int>((v - spec.lo[a]) / size[a] * dims[a]);
    return std::clamp(c, 0, dims[a] - 1);
  };
  auto cell_index = [&](const Eigen::Vector3d& c) {
    return (coord(c.z(), 2) * dims[1] + coord(c.y(), 1)) * dims[0] + coord(c.x(), 0);
  };

  // 1. Random sequential addition at shrunken radii s r, s^3 = rsa_fraction / solid fraction,
  // cell by cell: every cell receives its share of the shuffled sizes (equal cells, equal
  // numbers, so the solid fraction is uniform), largest first; each sphere tries up to
  // rsa_attempts uniform positions in its cell and takes the first that overlaps no sphere placed
  // before it (at the shrunken radii; the last try if none does). The spheres then overlap at
  // full size by at most (1 - s) of their radii sums, only with near neighbours, and the
  // relaxation below has little left to do (uniform random centres overlap without bound).
  // The cells are filled in eight passes by the parity of their indices, each pass in cell order:
  // a cell's neighbours on both sides of an axis are then both filled or both empty (filling in
  // plain cell order pushed every cell's spheres towards its empty side and left the last layer
  // at the far walls 4 % denser), and an attempt reads neighbours that are in cache (random order
  // over 10^6 spheres is bound by memory latency). The spheres come out in cell order.
  const double rsa_fraction = 0.2;
  const double shrink = std::min(1.0, std::cbrt(rsa_fraction / (1.0 - spec.porosity)));
  const int rsa_attempts = 1000;
  std::vector<Eigen::Vector3d> x(n), dx(n);
  std::vector<int> cell_of(n), order(n);
  {
    std::vector<int> head(ncell, -1), next(n, -1);
    std::vector<int> cells;  // eight passes, one per parity class of (x, y, z) cell indices
    cells.reserve(ncell);
    for (int parity = 0; parity < 8; ++parity)
      for (int c = 0; c < ncell; ++c) {
        const int px = (c % dims[0]) & 1, py = ((c / dims[0]) % dims[1]) & 1,
                  pz = (c / (dims[0] * dims[1])) & 1;
        if (px + 2 * py + 4 * pz == parity) cells.push_back(c);
      }
    // Cell c holds spheres [first[c], first[c + 1]): shares proportional to the volume that
    // centres of the mean radius can reach in the cell (the cells at the walls lose a radius),
    // so that the centres are spread uniformly as uniform random placement would spread them.
    std::vector<int> first(ncell + 1, 0);
    {
      double r_mean = 0.0;
      for (const double r : radii) r_mean += r / n;
      std::vector<double> reach(ncell);
      double total = 0.0;
      for (int c = 0; c < ncell; ++c) {
        const int ic[3] = {c % dims[0], (c / dims[0]) % dims[1], c / (dims[0] * dims[1])};
        double v = 1.0;
        for (int k = 0; k < 3; ++k) {
          const double w = size[k] / dims[k];
          v *= std::max(0.0, std::min(spec.lo[k] + (ic[k] + 1) * w, spec.hi[k] - r_mean) -
                                 std::max(spec.lo[k] + ic[k] * w, spec.lo[k] + r_mean));
        }
        reach[c] = v;
        total += v;
      }
      double sum = 0.0;
      for (int c = 0; c < ncell; ++c) {
        sum += reach[c];
        first[c + 1] = static_cast<int>(std::llround(sum / total * n));
      }
      first[ncell] = n;
    }
    for (const int c : cells) {
      const int first_c = first[c], last = first[c + 1];
      std::sort(radii.begin() + first_c, radii.begin() + last, std::greater<>());
      const int ix = c % dims[0], iy = (c / dims[0]) % dims[1], iz = c / (dims[0] * dims[1]);
      const int ic[3] = {ix, iy, iz};
      for (int i = first_c; i < last; ++i) {
        double lo[3], span[3];
        for (int k = 0; k < 3; ++k) {
          const double w = size[k] / dims[k];
          lo[k] = std::max(spec.lo[k] + ic[k] * w, spec.lo[k] + radii[i]);
          span[k] = std::max(0.0, std::min(spec.lo[k] + (ic[k] + 1) * w, spec.hi[k] - radii[i]) - lo[k]);
        }
        Eigen::Vector3d q;
        for (int attempt = 0; attempt < rsa_attempts; ++attempt) {
          for (int k = 0; k < 3; ++k) q[k] = lo[k] + rng.uniform() * span[k];
          bool free = true;
          for (int z = std::max(iz - 1, 0); free && z <= std::min(iz + 1, dims[2] - 1); ++z)
            for (int y = std::max(iy - 1, 0); free && y <= std::min(iy + 1, dims[1] - 1); ++y)
              for (int xx = std::max(ix - 1, 0); free && xx <= std::min(ix + 1, dims[0] - 1); ++xx)
                for (int j = head[(z * dims[1] + y) * dims[0] + xx]; j >= 0; j = next[j]) {
                  const double rs = shrink * (radii[i] + radii[j]);
                  if ((q - x[j]).squaredNorm() < rs * rs) {
                    free = false;
                    break;
                  }
                }
          if (free) break;
        }
        x[i] = q;
        next[i] = head[c];
        head[c] = i;
      }
    }
  }

  // 2. Jacobi relaxation: every sphere that overlaps (or comes within a margin of) another is
  // pushed away from it by the share V_j / (V_i + V_j) of the overlap, all spheres at once, and
  // kept inside the box, until the largest overlap is below the bound. Pairs come from a
  // neighbour list (closer than the radii sum + skin), rebuilt when some sphere has moved by half
  // the skin since the last build. Only the spheres that can have changed are evaluated: those
  // that touched in the last sweep and their neighbours (a sphere that touched none and whose
  // neighbours did not move has the same, empty, push as before). Late sweeps work on the few
  // caged spheres that are left, not on all N. The result is that of the full Jacobi sweep and
  // does not depend on the thread count.
  std::vector<int> start(ncell + 1), items(n), fill(ncell), nbr_start(n + 1);
  std::vector<int> nbr;
  std::vector<Eigen::Vector3d> x_built(n);
  auto build_list = [&] {
    std::fill(start.begin(), start.end(), 0);
    for (int i = 0; i < n; ++i) {
      cell_of[i] = cell_index(x[i]);
      ++start[cell_of[i] + 1];
    }
    for (int c = 0; c < ncell; ++c) start[c + 1] += start[c];
    std::fill(fill.begin(), fill.end(), 0);
    for (int i = 0; i < n; ++i) items[start[cell_of[i]] + fill[cell_of[i]]++] = i;
    nbr.clear();
    for (int i = 0; i < n; ++i) {
      nbr_start[i] = static_cast<int>(nbr.size());
      const int cx = coord(x[i].x(), 0), cy = coord(x[i].y(), 1), cz = coord(x[i].z(), 2);
      for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, dims[2] - 1); ++z)
        for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, dims[1] - 1); ++y)
          for (int xx = std::max(cx - 1, 0); xx <= std::min(cx + 1, dims[0] - 1); ++xx) {
            const int c = (z * dims[1] + y) * dims[0] + xx;
            for (int k = start[c]; k < start[c + 1]; ++k) {
              const int j = items[k];
              if (j == i) continue;
              const double reach = radii[i] + radii[j] + skin;
              if ((x[i] - x[j]).squaredNorm() < reach * reach) nbr.push_back(j);
            }
          }
    }
    nbr_start[n] = static_cast<int>(nbr.size());
    x_built = x;
  };
  build_list();
  std::vector<int> active(n), touched;
  for (int i = 0; i < n; ++i) active[i] = i;
  std::vector<char> touching(n, 0), mark(n, 0);
  touched.reserve(n);
  Packing out;
  double worst = 0.0;
  int sweep = 0;
  for (; sweep < spec.max_sweeps; ++sweep) {
    // dx_i = sum_j w_i (delta_ij + margin) n_ij over the pairs closer than r_i + r_j + margin.
    worst = 0.0;
    const int na = static_cast<int>(active.size());
#pragma omp parallel for schedule(static, 1024) reduction(max : worst) if (na >= 4096)
    for (int a = 0; a < na; ++a) {
      const int i = active[a];
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      bool touches = false;
      const double ri3 = radii[i] * radii[i] * radii[i];
      for (int k = nbr_start[i]; k < nbr_start[i + 1]; ++k) {
        const int j = nbr[k];
        const Eigen::Vector3d rij = x[i] - x[j];
        const double rs = radii[i] + radii[j];
        const double r2 = rij.squaredNorm();
        if (r2 >= rs * rs) continue;
        const double r = std::sqrt(r2);
        const double delta = rs - r;
        worst = std::max(worst, delta);
        const double rj3 = radii[j] * radii[j] * radii[j];
        const Eigen::Vector3d nrm =
            r > 0.0 ? Eigen::Vector3d(rij / r) : Eigen::Vector3d(i < j ? 1.0 : -1.0, 0, 0);
        d += (rj3 / (ri3 + rj3)) * (delta + margin) * nrm;
        touches = true;
      }
      dx[i] = d;
      touching[i] = touches;
    }
    if (spec.progress) spec.progress(sweep, worst / r_min);
    if (worst <= bound) break;
    touched.clear();
    for (int a = 0; a < na; ++a)
      if (touching[active[a]]) touched.push_back(active[a]);
    double moved = 0.0;
    const int nt = static_cast<int>(touched.size());
#pragma omp parallel for schedule(static, 1024) reduction(max : moved) if (nt >= 4096)
    for (int a = 0; a < nt; ++a) {
      const int i = touched[a];
      x[i] += dx[i];
      for (int c = 0; c < 3; ++c)
        x[i][c] = std::clamp(x[i][c], spec.lo[c] + radii[i], spec.hi[c] - radii[i]);
      moved = std::max(moved, (x[i] - x_built[i]).squaredNorm());
    }
    if (4.0 * moved >= skin * skin) build_list();
    // Next sweep: the touching spheres and their neighbours (all of them while many touch).
    if (8 * nt >= n) {
      active.resize(n);
      for (int i = 0; i < n; ++i) active[i] = i;
    } else {
      for (const int i : touched) {
        mark[i] = 1;
        for (int k = nbr_start[i]; k < nbr_start[i + 1]; ++k) mark[nbr[k]] = 1;
      }
      active.clear();
      for (int i = 0; i < n; ++i)
        if (mark[i]) {
          active.push_back(i);
          mark[i] = 0;
        }
    }
  }
  if (worst > bound) {
    std::ostringstream m2;
    m2 << "packing: overlaps still up to " << worst / r_min << " R_min after " << spec.max_sweeps
       << " sweeps (allowed " << spec.max_overlap << "); raise the porosity or max_sweeps";
    throw Error(m2.str());
  }
  // Output in cell order (z, then y, then x): neighbours get nearby indices, which keeps the
  // solver's neighbour data in cache and its thread parts compact.
  for (int i = 0; i < n; ++i) {
    order[i] = i;
    cell_of[i] = cell_index(x[i]);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return cell_of[a] < cell_of[b]; });
  out.positions.resize(n, 3);
  out.radii.resize(n);
  double vs = 0.0;
  for (int k = 0; k < n; ++k) {
    const int i = order[k];
    out.positions.row(k) = x[i].transpose();
    out.radii[k] = radii[i];
    vs += 4.0 / 3.0 * std::numbers::pi * radii[i] * radii[i] * radii[i];
  }
  out.porosity = 1.0 - vs / box_volume;
  out.max_overlap = std::max(worst, 0.0);
  out.sweeps = sweep;
  return out;
}

}  // namespace partita::dem
