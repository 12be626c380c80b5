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
  std::vector<Eigen::Vector3d> x(n), dx(n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      x[i][a] = spec.lo[a] + radii[i] + rng.uniform() * (size[a] - 2.0 * radii[i]);

  const double r_min = *std::min_element(radii.begin(), radii.end());
  const double r_max = *std::max_element(radii.begin(), radii.end());
  const double bound = spec.max_overlap * r_min;
  const double margin = 0.2 * bound;  // push pairs a little apart: converges faster
  // Cells of size 2 R_max over the box (particles never leave it).
  const double cell = 2.0 * r_max;
  int dims[3];
  for (int a = 0; a < 3; ++a) dims[a] = std::max(1, static_cast<int>(size[a] / cell));
  const int ncell = dims[0] * dims[1] * dims[2];
  std::vector<int> start(ncell + 1), items(n), cell_of(n), fill(ncell);
  auto coord = [&](double v, int a) {
    const int c = static_cast<int>((v - spec.lo[a]) / size[a] * dims[a]);
    return std::clamp(c, 0, dims[a] - 1);
  };
  Packing out;
  double worst = 0.0;
  int sweep = 0;
  for (; sweep < spec.max_sweeps; ++sweep) {
    std::fill(start.begin(), start.end(), 0);
    for (int i = 0; i < n; ++i) {
      cell_of[i] =
          (coord(x[i].z(), 2) * dims[1] + coord(x[i].y(), 1)) * dims[0] + coord(x[i].x(), 0);
      ++start[cell_of[i] + 1];
    }
    for (int c = 0; c < ncell; ++c) start[c + 1] += start[c];
    std::fill(fill.begin(), fill.end(), 0);
    for (int i = 0; i < n; ++i) items[start[cell_of[i]] + fill[cell_of[i]]++] = i;
    // Jacobi sweep: dx_i = sum_j w_i (delta_ij + margin) n_ij, w_i = V_j/(V_i + V_j).
    worst = 0.0;
#pragma omp parallel for schedule(dynamic, 256) reduction(max : worst) if (n >= 1024)
    for (int i = 0; i < n; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      const int cx = coord(x[i].x(), 0), cy = coord(x[i].y(), 1), cz = coord(x[i].z(), 2);
      const double ri3 = radii[i] * radii[i] * radii[i];
      for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, dims[2] - 1); ++z)
        for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, dims[1] - 1); ++y)
          for (int xx = std::max(cx - 1, 0); xx <= std::min(cx + 1, dims[0] - 1); ++xx) {
            const int c = (z * dims[1] + y) * dims[0] + xx;
            for (int k = start[c]; k < start[c + 1]; ++k) {
              const int j = items[k];
              if (j == i) continue;
              const Eigen::Vector3d rij = x[i] - x[j];
              const double rs = radii[i] + radii[j];
              const double r2 = rij.squaredNorm();
              if (r2 >= (rs + margin) * (rs + margin)) continue;
              const double r = std::sqrt(r2);
              const double delta = rs - r;
              worst = std::max(worst, delta);
              const double rj3 = radii[j] * radii[j] * radii[j];
              const Eigen::Vector3d nrm =
                  r > 0.0 ? Eigen::Vector3d(rij / r) : Eigen::Vector3d(i < j ? 1.0 : -1.0, 0, 0);
              d += (rj3 / (ri3 + rj3)) * (delta + margin) * nrm;
            }
          }
      dx[i] = d;
    }
    if (spec.progress) spec.progress(sweep, worst / r_min);
    if (worst <= bound) break;
    for (int i = 0; i < n; ++i) {
      x[i] += dx[i];
      for (int a = 0; a < 3; ++a)
        x[i][a] = std::clamp(x[i][a], spec.lo[a] + radii[i], spec.hi[a] - radii[i]);
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
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) {
    order[i] = i;
    cell_of[i] = (coord(x[i].z(), 2) * dims[1] + coord(x[i].y(), 1)) * dims[0] + coord(x[i].x(), 0);
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
